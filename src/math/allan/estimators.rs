//! The time-domain stability estimators the field uses, as NIST SP 1065 (Riley, *Handbook of
//! Frequency Stability Analysis*, 2008) defines them and Stable32 and allantools name them: Allan
//! (non-overlapping and overlapping), modified Allan, time deviation, Hadamard (non-overlapping
//! and overlapping) and total deviation, all from phase data x (the cumulative sum of the rate y
//! times τ0, N points), at τ = m·τ0.
//!
//! Each returns the variance and the number of terms it averaged (what the EDF needs), or None where
//! the estimator is not defined at that m for that length (too few terms): a short series is
//! analysed as far as it goes, not refused.

use super::edf::{Alpha, identify_noise};

/// Which estimator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Estimator {
    /// Allan deviation, non-overlapping (SP 1065 eq. 6).
    Adev,
    /// Allan deviation, overlapping (SP 1065 eq. 11): the default.
    Oadev,
    /// Modified Allan deviation (SP 1065 eq. 14).
    Mdev,
    /// Time deviation, τ/√3 · MDEV (SP 1065 eq. 15), in units of time (phase).
    Tdev,
    /// Hadamard deviation, non-overlapping (SP 1065 eq. 17).
    Hdev,
    /// Hadamard deviation, overlapping (SP 1065 eq. 18).
    Ohdev,
    /// Total deviation (SP 1065 eq. 25), the phase extended by reflection at both ends.
    Totdev,
}

impl Estimator {
    /// Every estimator, in the order above.
    pub const ALL: [Self; 7] = [Self::Adev, Self::Oadev, Self::Mdev, Self::Tdev, Self::Hdev, Self::Ohdev, Self::Totdev];

    /// The name as Stable32 and allantools spell it (`adev`, `oadev`, ...).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Adev => "adev",
            Self::Oadev => "oadev",
            Self::Mdev => "mdev",
            Self::Tdev => "tdev",
            Self::Hdev => "hdev",
            Self::Ohdev => "ohdev",
            Self::Totdev => "totdev",
        }
    }

    /// The estimator named `name`.
    #[must_use]
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|e| e.name() == name)
    }

    /// The variance at τ = m·τ0 of the phase `x` (N points, τ0 apart) and the number of terms
    /// averaged; None where it is not defined (m = 0, or too few points for one term; TOTDEV up
    /// to m = N − 2, the reflection's reach).
    #[must_use]
    pub fn variance(self, x: &[f64], tau0_s: f64, m: usize) -> Option<(f64, usize)> {
        let n = x.len();
        if m == 0 || n < 2 {
            return None;
        }
        let tau = m as f64 * tau0_s;
        let second = |i: usize| x[i + 2 * m] - 2.0 * x[i + m] + x[i];
        let third = |i: usize| x[i + 3 * m] - 3.0 * x[i + 2 * m] + 3.0 * x[i + m] - x[i];
        let mean_of = |terms: &mut dyn Iterator<Item = f64>| -> Option<(f64, usize)> {
            let (sum, count) = terms.fold((0.0, 0usize), |(s, c), v| (s + v * v, c + 1));
            (count > 0).then(|| (sum / count as f64, count))
        };
        match self {
            Self::Oadev => {
                let (mean, count) = mean_of(&mut (0..n.checked_sub(2 * m)?).map(second))?;
                Some((mean / (2.0 * tau * tau), count))
            }
            Self::Adev => {
                let (mean, count) = mean_of(&mut (0..n.checked_sub(2 * m)?).step_by(m).map(second))?;
                Some((mean / (2.0 * tau * tau), count))
            }
            Self::Ohdev => {
                let count = n.checked_sub(3 * m).filter(|c| *c > 0)?;
                let sum = super::sum_sq_third_diff(
                    &x[..count],
                    &x[m..m + count],
                    &x[2 * m..2 * m + count],
                    &x[3 * m..3 * m + count],
                );
                Some((sum / count as f64 / (6.0 * tau * tau), count))
            }
            Self::Hdev => {
                let (mean, count) = mean_of(&mut (0..n.checked_sub(3 * m)?).step_by(m).map(third))?;
                Some((mean / (6.0 * tau * tau), count))
            }
            Self::Mdev | Self::Tdev => {
                // Running sum over j..j+m of the second differences: s_j = Σ_{i=j}^{j+m−1} d_i.
                let terms = (n + 1).checked_sub(3 * m)?;
                if terms == 0 {
                    return None;
                }
                let mut s: f64 = (0..m).map(second).sum();
                let mut sum = s * s;
                for j in 1..terms {
                    s += second(j + m - 1) - second(j - 1);
                    sum += s * s;
                }
                let mvar = sum / (2.0 * (m * m) as f64 * tau * tau * terms as f64);
                Some(if self == Self::Tdev { (tau * tau / 3.0 * mvar, terms) } else { (mvar, terms) })
            }
            Self::Totdev => {
                // SP 1065 eq. 25: x*_{1−j} = 2x_1 − x_{1+j}, x*_{N+j} = 2x_N − x_{N−j}, j = 1..N−2;
                // Σ_{i=2}^{N−1} [x*_{i−m} − 2x*_i + x*_{i+m}]² / (2τ²(N − 2)).
                if n < 3 || m > n - 2 {
                    return None;
                }
                let at = |k: isize| -> f64 {
                    let last = n as isize - 1;
                    if k < 0 {
                        2.0 * x[0] - x[(-k) as usize]
                    } else if k > last {
                        2.0 * x[last as usize] - x[(2 * last - k) as usize]
                    } else {
                        x[k as usize]
                    }
                };
                // i = 1..=N−2 (0-based): where m ≤ i ≤ N−1−m no reflection is reached and the
                // terms are OADEV's second differences (one fused pass); the ends go through `at`.
                let mi = m as isize;
                let last = n as isize - 1;
                let (lo, hi) = (mi.max(1), (last - mi).min(last - 1));
                let term = |i: isize| (at(i - mi) - 2.0 * at(i) + at(i + mi)).powi(2);
                let sum: f64 = if lo <= hi {
                    let (a, b) = ((lo - mi) as usize, (hi - mi) as usize + 1);
                    super::sum_sq_second_diff(&x[a..b], &x[a + m..b + m], &x[a + 2 * m..b + 2 * m])
                        + (1..lo).map(term).sum::<f64>()
                        + (hi + 1..last).map(term).sum::<f64>()
                } else {
                    (1..last).map(term).sum()
                };
                Some((sum / (2.0 * tau * tau * (n - 2) as f64), n - 2))
            }
        }
    }
}

/// One estimator's curve over a set of averaging factors, with its confidence intervals.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DeviationCurve {
    /// Which estimator.
    pub estimator: Estimator,
    /// Averaging factors m where the estimator is defined.
    pub m: Vec<usize>,
    /// τ = m·τ0, s.
    pub taus_s: Vec<f64>,
    /// The deviation: of the rate (SI rate unit) for every estimator but TDEV, which is of the
    /// phase (SI phase unit: s, rad, m/s).
    pub dev: Vec<f64>,
    /// Lower confidence bound at −`ci_sigma` (the unit of `dev`).
    pub lower: Vec<f64>,
    /// Upper confidence bound at +`ci_sigma`.
    pub upper: Vec<f64>,
    /// Equivalent degrees of freedom ([`Estimator::edf`]).
    pub edf: Vec<f64>,
    /// The noise type α the EDF assumed.
    pub alpha: Vec<Alpha>,
    /// α identified at this τ (else carried from the last τ where it was, or white FM if none).
    pub alpha_identified: Vec<bool>,
    /// Terms averaged.
    pub n_terms: Vec<usize>,
}

impl Estimator {
    /// The largest m where the estimator is defined for `n` phase points (at least one term).
    #[must_use]
    pub fn max_m(self, n: usize) -> usize {
        match self {
            Self::Adev | Self::Oadev => n.saturating_sub(1) / 2,
            Self::Hdev | Self::Ohdev => n.saturating_sub(1) / 3,
            Self::Mdev | Self::Tdev => n / 3,
            Self::Totdev => n.saturating_sub(2),
        }
    }

    /// What the deviation is of ("the rate"; TDEV: "the phase").
    #[must_use]
    pub fn is_of_phase(self) -> bool {
        self == Self::Tdev
    }

    /// The name a reader knows it by.
    #[must_use]
    pub fn title(self) -> &'static str {
        match self {
            Self::Adev => "Allan deviation (non-overlapping)",
            Self::Oadev => "Allan deviation (overlapping)",
            Self::Mdev => "modified Allan deviation",
            Self::Tdev => "time deviation",
            Self::Hdev => "Hadamard deviation (non-overlapping)",
            Self::Ohdev => "Hadamard deviation (overlapping)",
            Self::Totdev => "total deviation",
        }
    }
}

/// The curve of `estimator` on the phase `x` (N points τ0 apart) at the averaging factors `ms`
/// (those where it is not defined skipped), with ±`ci_sigma` χ² intervals from its EDF for the
/// noise identified at each τ ([`identify_noise`]). OADEV takes the fused O(N) pass of the IMU
/// analysis; the others their definitions.
#[must_use]
pub fn deviation_curve(estimator: Estimator, x: &[f64], tau0_s: f64, ms: &[usize], ci_sigma: f64) -> DeviationCurve {
    let ms: Vec<usize> = ms.iter().copied().filter(|&m| m >= 1 && m <= estimator.max_m(x.len())).collect();
    let variances: Vec<Option<(f64, usize)>> = if estimator == Estimator::Oadev {
        super::second_difference_sums(x, &ms)
            .into_iter()
            .zip(&ms)
            .map(|((s, terms), &m)| Some((s / (2.0 * (m as f64 * tau0_s).powi(2) * terms as f64), terms)))
            .collect()
    } else {
        ms.iter().map(|&m| estimator.variance(x, tau0_s, m)).collect()
    };
    let mut c = DeviationCurve {
        estimator,
        m: vec![],
        taus_s: vec![],
        dev: vec![],
        lower: vec![],
        upper: vec![],
        edf: vec![],
        alpha: vec![],
        alpha_identified: vec![],
        n_terms: vec![],
    };
    let mut last_alpha = None;
    for (&m, v) in ms.iter().zip(variances) {
        let Some((var, terms)) = v else { continue };
        let found = identify_noise(x, m, estimator);
        let alpha = found.or(last_alpha).unwrap_or(0);
        last_alpha = Some(alpha);
        let edf = estimator.edf(alpha, m, x.len()).unwrap_or(1.0);
        let dev = var.max(0.0).sqrt();
        let (lo, hi) = super::adev_confidence(dev, edf, ci_sigma);
        c.m.push(m);
        c.taus_s.push(m as f64 * tau0_s);
        c.dev.push(dev);
        c.lower.push(lo);
        c.upper.push(hi);
        c.edf.push(edf);
        c.alpha.push(alpha);
        c.alpha_identified.push(found.is_some());
        c.n_terms.push(terms);
    }
    c
}

/// Phase from a rate series y (fractional frequency, rad/s, m/s², ...) every τ0: x_0 = 0,
/// x_k = τ0 Σ_{i<k} y_i (N + 1 points).
#[must_use]
pub fn phase_of_rates(y: &[f64], tau0_s: f64) -> Vec<f64> {
    let mut x = Vec::with_capacity(y.len() + 1);
    let mut acc = 0.0;
    x.push(0.0);
    for v in y {
        acc += v * tau0_s;
        x.push(acc);
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// NBS14's 9 frequency values (NIST SP 1065 §12.2's test suite, from Riley's handbook and
    /// the NBS Monograph 140 data), τ0 = 1.
    const NBS14_F: [f64; 9] = [892.0, 809.0, 823.0, 798.0, 671.0, 644.0, 883.0, 903.0, 677.0];

    /// The published deviations at τ = 1 and 2 (NIST SP 1065 p. 107, Table 31; Stable32), printed
    /// to 7 significant digits: a relative agreement of 1e-6 is what the print allows.
    const NBS14_DEVS: [(Estimator, f64, f64); 7] = [
        (Estimator::Adev, 91.22945, 115.8082),
        (Estimator::Oadev, 91.22945, 85.95287),
        (Estimator::Mdev, 91.22945, 74.78849),
        (Estimator::Tdev, 52.67135, 86.35831),
        (Estimator::Hdev, 70.80608, 116.7980),
        (Estimator::Ohdev, 70.80607, 85.61487),
        (Estimator::Totdev, 91.22945, 93.90379),
    ];

    #[test]
    fn nbs14_deviations_match_the_published_table() {
        let x = phase_of_rates(&NBS14_F, 1.0);
        for (est, d1, d2) in NBS14_DEVS {
            for (m, want) in [(1, d1), (2, d2)] {
                let (var, _) = est.variance(&x, 1.0, m).unwrap_or_else(|| panic!("{} defined at m = {m}", est.name()));
                let got = var.sqrt();
                assert!((got / want - 1.0).abs() < 1.5e-6, "{} m = {m}: {got} vs the published {want}", est.name());
            }
        }
    }

    /// The 1000-point NBS14 set (NIST SP 1065 p. 107): n_0 = 1234567890, n_{i+1} = 16807·n_i mod
    /// (2³¹ − 1), y_i = n_i / (2³¹ − 1).
    fn nbs14_1000() -> Vec<f64> {
        let mut n = 1_234_567_890u64;
        let mut y = Vec::with_capacity(1000);
        for i in 0..1000 {
            if i == 3 {
                // The handbook prints n_1, n_2, n_3 to check the generator.
                assert_eq!(n, 633_705_974);
            }
            y.push(n as f64 / 2_147_483_647.0);
            n = 16_807 * n % 2_147_483_647;
        }
        y
    }

    #[test]
    fn nbs14_1000_point_deviations_match_the_published_table() {
        // NIST SP 1065 p. 108 (Riley, Table III of "The calculation of time domain frequency
        // stability"), τ = 1, 10, 100; printed to 7 digits. TOTDEV is the doubly reflected method.
        let table: [(Estimator, [f64; 3]); 7] = [
            (Estimator::Adev, [2.922319e-01, 9.965736e-02, 3.897804e-02]),
            (Estimator::Oadev, [2.922319e-01, 9.159953e-02, 3.241343e-02]),
            (Estimator::Mdev, [2.922319e-01, 6.172376e-02, 2.170921e-02]),
            (Estimator::Tdev, [1.687202e-01, 3.563623e-01, 1.253382e+00]),
            (Estimator::Hdev, [2.943883e-01, 1.052754e-01, 3.910860e-02]),
            (Estimator::Ohdev, [2.943883e-01, 9.581083e-02, 3.237638e-02]),
            (Estimator::Totdev, [2.922319e-01, 9.134743e-02, 3.406530e-02]),
        ];
        let x = phase_of_rates(&nbs14_1000(), 1.0);
        for (est, devs) in table {
            for (m, want) in [1, 10, 100].into_iter().zip(devs) {
                let got = est.variance(&x, 1.0, m).expect("defined").0.sqrt();
                assert!((got / want - 1.0).abs() < 2e-6, "{} m = {m}: {got:e} vs the published {want:e}", est.name());
            }
        }
    }

    #[test]
    fn a_short_series_is_analysed_as_far_as_each_estimator_goes() {
        let x = phase_of_rates(&NBS14_F, 1.0); // 10 phase points
        // OADEV needs 2m < N; OHDEV 3m < N; MDEV 3m ≤ N; TOTDEV m ≤ N − 2.
        assert!(Estimator::Oadev.variance(&x, 1.0, 4).is_some() && Estimator::Oadev.variance(&x, 1.0, 5).is_none());
        assert!(Estimator::Ohdev.variance(&x, 1.0, 3).is_some() && Estimator::Ohdev.variance(&x, 1.0, 4).is_none());
        assert!(Estimator::Mdev.variance(&x, 1.0, 3).is_some() && Estimator::Mdev.variance(&x, 1.0, 4).is_none());
        assert!(Estimator::Totdev.variance(&x, 1.0, 8).is_some() && Estimator::Totdev.variance(&x, 1.0, 9).is_none());
        assert!(Estimator::Adev.variance(&x, 1.0, 0).is_none());
    }

    #[test]
    fn mdev_falls_faster_than_adev_on_white_phase_noise() {
        // White phase noise: MDEV falls as τ^{-3/2} where ADEV falls as τ^{-1} (SP 1065 Table 2
        // slopes): at m = 16 their ratio is below 0.35, a check that the two differ as they must.
        let mut s = 12345u64;
        let mut uniform = move || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((s >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        let x: Vec<f64> =
            (0..20_000).map(|_| (-2.0 * uniform().ln()).sqrt() * (std::f64::consts::TAU * uniform()).cos()).collect();
        let a = Estimator::Oadev.variance(&x, 1.0, 16).expect("defined").0.sqrt();
        let md = Estimator::Mdev.variance(&x, 1.0, 16).expect("defined").0.sqrt();
        assert!(md / a < 0.35, "mdev/adev {}", md / a);
    }
}
