//! Tests of the Allan analysis that need no sensor model: the estimator against its definition,
//! the EDF and χ² against their tables, the fit on exact curves, white noise against N/√τ.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

use super::*;

fn normal(rng: &mut ChaCha8Rng) -> f64 {
    rng.sample(StandardNormal)
}

/// Mixed test signal (rad per sample): white rate, random-walk rate, a sinusoid, a ramp and a bias
/// 10³ × the white level (to stress the cancellation in the cumulative sums).
fn mixed_increments(n: usize, tau0_s: f64, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut rw = 0.0;
    (0..n)
        .map(|k| {
            let t = k as f64 * tau0_s;
            rw += 1e-7 * normal(&mut rng);
            let rate = 1e-3 + 1e-6 * normal(&mut rng) + rw + 3e-7 * (0.7 * t).sin() + 1e-9 * t;
            rate * tau0_s
        })
        .collect()
}

/// Golden: the definition itself, IEEE 952-1997 Annex C / NIST SP 1065 eq. (11), overlapped:
/// averages ȳ_j(m) of the rate over every window of m samples, σ² = Σ_j (ȳ_{j+m} − ȳ_j)² / (2(N − 2m + 1)),
/// each average summed directly (O(N·m), no cumulative sum).
fn direct_avar(increments: &[f64], tau0_s: f64, m: usize) -> f64 {
    let y: Vec<f64> = increments.iter().map(|d| d / tau0_s).collect();
    let avg = |j: usize| y[j..j + m].iter().sum::<f64>() / m as f64;
    let terms = y.len() - 2 * m + 1;
    let sum: f64 = (0..terms).map(|j| (avg(j + m) - avg(j)).powi(2)).sum();
    sum / (2.0 * terms as f64)
}

#[test]
fn fast_adev_matches_direct_cluster_averages_to_1e9_at_every_tau() {
    let tau0_s = 0.01;
    let inc = mixed_increments(3000, tau0_s, 7);
    let phase = Phase::from_increments(&inc);
    for spacing in [
        TauSpacing::Octave,
        TauSpacing::PerDecade(20),
        TauSpacing::Explicit((1..=40).chain([333, 500, 749, 750]).collect()),
    ] {
        let opts = AllanOptions { spacing, ..AllanOptions::default() };
        let curve = allan_curve(&phase, tau0_s, &opts).expect("valid input");
        assert!(curve.m.len() > 5 && *curve.m.last().expect("points") <= 750);
        for (j, &m) in curve.m.iter().enumerate() {
            let direct = direct_avar(&inc, tau0_s, m);
            let rel = (curve.avar_si[j] / direct - 1.0).abs();
            assert!(rel < 1e-9, "m = {m}: fast {} direct {direct} rel {rel:e}", curve.avar_si[j]);
            assert_eq!(curve.n_terms[j], 3000 + 1 - 2 * m);
        }
    }
}

#[test]
fn a_large_constant_in_the_signal_changes_nothing() {
    // Gravity in Δv (9.8 m/s² · 5 ms per sample) under 2e-5 m/s of noise: the phase is taken
    // relative to the first sample, so the curve is the one of the noise alone (to rounding).
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let noise: Vec<f64> = (0..200_000).map(|_| 2e-5 * normal(&mut rng)).collect();
    let with_g: Vec<f64> = noise.iter().map(|x| x + 9.806_65 * 0.005).collect();
    let o = AllanOptions::default();
    let a = allan_curve(&Phase::from_increments(&noise), 0.005, &o).expect("ok");
    let b = allan_curve(&Phase::from_increments(&with_g), 0.005, &o).expect("ok");
    for (x, y) in a.avar_si.iter().zip(&b.avar_si) {
        assert!((x / y - 1.0).abs() < 1e-9, "{x} vs {y}");
    }
}

#[test]
fn cluster_sizes_follow_spacing_and_limit() {
    let oct = cluster_sizes(1000, &TauSpacing::Octave, 4).expect("ok");
    assert_eq!(oct, vec![1, 2, 4, 8, 16, 32, 64, 128]); // 256 > 1000/4
    let dec = cluster_sizes(400, &TauSpacing::PerDecade(10), 4).expect("ok");
    // round(10^(i/10)): 1 1 2 2 3 3 4 5 6 8 10 13 16 20 25 32 40 50 63 79 100
    assert_eq!(dec, vec![1, 2, 3, 4, 5, 6, 8, 10, 13, 16, 20, 25, 32, 40, 50, 63, 79, 100]);
    let exp = cluster_sizes(100, &TauSpacing::Explicit(vec![0, 7, 3, 7, 51]), 2).expect("ok");
    assert_eq!(exp, vec![3, 7]);
    assert!(cluster_sizes(100, &TauSpacing::Octave, 1).is_err());
    assert!(cluster_sizes(100, &TauSpacing::PerDecade(0), 4).is_err());
}

#[test]
fn edf_matches_sp1065_table5_formulas() {
    // Golden: NIST SP 1065 Table 5 formulas evaluated independently (Python) for N = 1025 phase
    // points (1024 samples).
    let cases = [
        (1, NoiseType::WhiteRate, 681.779_512_195_121_9),
        (10, NoiseType::WhiteRate, 149.732_249_322_493_2),
        (1, NoiseType::FlickerRate, 889.678_653_404_743_7),
        (2, NoiseType::FlickerRate, 636.896_823_472_356_9),
        (100, NoiseType::RandomWalkRate, 7.653_038_706_193_681),
        (10, NoiseType::WhitePhase, 507.945_812_807_881_8),
    ];
    for (m, t, want) in cases {
        let got = edf_overlapping(1024, m, t);
        assert!((got / want - 1.0).abs() < 1e-12, "{t:?} m={m}: {got} vs {want}");
    }
    assert!(edf_overlapping(1024, 256, NoiseType::FlickerPhase) >= 1.0);
}

#[test]
fn chi2_wilson_hilferty_matches_tables() {
    // Golden: χ² critical values, NIST/SEMATECH e-Handbook of Statistical Methods table 1.3.6.7.4.
    let cases = [
        (10.0, 1.644_854, 18.307),
        (10.0, -1.644_854, 3.940),
        (100.0, 1.959_964, 129.561),
        (100.0, -1.959_964, 74.222),
        (30.0, 2.326_348, 50.892),
    ];
    for (nu, z, want) in cases {
        let got = chi2_quantile(nu, z);
        assert!((got / want - 1.0).abs() < 5e-3, "nu={nu} z={z}: {got} vs {want}");
    }
    let (lo, hi) = adev_confidence(2.0, 50.0, 1.0);
    assert!(lo < 2.0 && hi > 2.0 && hi - 2.0 > 2.0 - lo);
}

#[test]
fn white_noise_follows_n_over_root_tau_within_its_confidence() {
    // Golden: IEEE 952-1997 C.1.2, σ(τ) = N/√τ for white rate noise of density N. 1 h at 200 Hz
    // of N = 1e-4 rad/√s. At every τ the relative scatter of the estimate is 1/√(2·EDF) (χ² with
    // EDF degrees of freedom, white-rate EDF of SP 1065 Table 5): each point within 4 of those
    // (a false alarm over the 20 points has probability ~1e-3), and the fit's N within 1 %.
    let (tau0_s, n_si) = (0.005f64, 1e-4);
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let inc: Vec<f64> = (0..720_000).map(|_| n_si * tau0_s.sqrt() * normal(&mut rng)).collect();
    let r = analyze(&Phase::from_increments(&inc), tau0_s, &AllanOptions::default()).expect("ok");
    assert!(r.taus_s.len() >= 15);
    let mut worst = 0.0f64;
    for (j, (&tau, &adev)) in r.taus_s.iter().zip(&r.adev_si).enumerate() {
        let sigma =
            1.0 / (2.0 * edf_overlapping(r.n_samples, (tau / tau0_s).round() as usize, NoiseType::WhiteRate)).sqrt();
        let rel = adev / (n_si / tau.sqrt()) - 1.0;
        worst = worst.max(rel.abs() / sigma);
        assert!(rel.abs() < 4.0 * sigma, "tau {tau} s (point {j}): {rel:+.4} outside ±{:.4}", 4.0 * sigma);
    }
    eprintln!(
        "white noise: worst point {worst:.2}σ from N/√τ over {} cluster times; fitted N/true {:.5}",
        r.taus_s.len(),
        r.fit.n_si.value / n_si
    );
    assert!((r.fit.n_si.value / n_si - 1.0).abs() < 0.01, "N {}", r.fit.n_si.value);
    assert_eq!(r.fit.significant_terms(), vec![NoiseTerm::RandomWalk]);
}

#[test]
fn one_sigma_interval_covers_truth_68_percent_of_the_time() {
    // Golden: the 1σ interval should contain the true ADEV N/√τ in 68.3 % of independent
    // white-noise records; 300 records → ±2.7 % binomial σ, so ±9 % is a 3σ band.
    let (tau0_s, n_rec, len) = (0.01f64, 300, 2048);
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let n_si = 1e-3;
    let mut hits = [0usize; 3];
    for _ in 0..n_rec {
        let inc: Vec<f64> = (0..len).map(|_| n_si * tau0_s.sqrt() * normal(&mut rng)).collect();
        let r = analyze(&Phase::from_increments(&inc), tau0_s, &AllanOptions::default()).expect("ok");
        for (h, j) in hits.iter_mut().zip([0usize, 5, 8]) {
            let truth = n_si / r.taus_s[j].sqrt();
            *h += usize::from(r.adev_lower_si[j] <= truth && truth <= r.adev_upper_si[j]);
        }
    }
    for h in hits {
        let frac = h as f64 / n_rec as f64;
        assert!((frac - 0.683).abs() < 0.09, "coverage {frac}");
    }
}

fn synthetic_curve(coef: [f64; 5], n_samples: usize, tau0_s: f64) -> AllanCurve {
    let m = cluster_sizes(n_samples, &TauSpacing::PerDecade(5), 4).expect("ok");
    let taus_s: Vec<f64> = m.iter().map(|&m| m as f64 * tau0_s).collect();
    let avar_si = taus_s.iter().map(|&t| TERMS.iter().zip(coef).map(|(term, c)| term.avar(c, t)).sum()).collect();
    let n_terms = m.iter().map(|&m| n_samples + 1 - 2 * m).collect();
    AllanCurve { tau0_s, n_samples, m, taus_s, avar_si, n_terms }
}

#[test]
fn fit_recovers_an_exact_power_law_curve() {
    // Golden: the curve is built from the IEEE 952 C.1 formulas with these coefficients, dominating
    // in turn: Q below 0.33 s, N 0.33-5 s, B 5-530 s, K 530-6700 s, R above (curve up to 62 500 s).
    let coef = [1e-6, 3e-6, 2e-6, 1e-7, 1e-9];
    let curve = synthetic_curve(coef, 50_000_000, 0.005);
    let fit = fit_noise_model(&curve);
    for (term, want) in TERMS.iter().zip(coef) {
        let e = fit.coefficients.get(*term);
        assert!((e.value / want - 1.0).abs() < 1e-6, "{term:?}: {} vs {want}", e.value);
        assert!(e.significant, "{term:?}");
    }
}

#[test]
fn slope_reading_of_pure_terms_is_exact() {
    // Golden: IEEE 952-1997 C.1 term formulas; the slope-line reading of a pure power law returns
    // its coefficient exactly.
    for (k, term) in TERMS.iter().enumerate() {
        let mut coef = [0.0; 5];
        coef[k] = 2e-6;
        let c = synthetic_curve(coef, 1_000_000, 0.01);
        let adev: Vec<f64> = c.avar_si.iter().map(|v| v.sqrt()).collect();
        let r = slope_readings(&c.taus_s, &adev, &adev, &adev);
        let s = r.get(*term).expect("reading");
        assert!((s.value_si / 2e-6 - 1.0).abs() < 1e-12 && s.matched, "{term:?} {s:?}");
    }
}

#[test]
fn gauss_markov_series_and_closed_form_meet() {
    let (a, b) = (gauss_markov_avar(1.0, 1.0, 0.999_999e-2), gauss_markov_avar(1.0, 1.0, 1.000_001e-2));
    assert!((a / b - 1.0).abs() < 1e-5);
    // Limits (IEEE 952 C.1.6): 2σ²T/τ for τ ≫ T, (2/3)σ²τ/T for τ ≪ T.
    assert!((gauss_markov_avar(1.0, 1.0, 1e4) / (2.0 / 1e4) - 1.0).abs() < 1e-3);
    assert!((gauss_markov_avar(1.0, 1.0, 1e-4) / (2.0 / 3.0 * 1e-4) - 1.0).abs() < 1e-3);
}

#[test]
fn constant_input_gives_a_zero_curve_and_no_terms() {
    let r = analyze(&Phase::from_increments(&[1e-5; 100]), 0.01, &AllanOptions::default()).expect("ok");
    assert!(r.adev_si.iter().all(|&a| a == 0.0));
    assert!(r.fit.significant_terms().is_empty());
    assert!(r.adev_upper_si.iter().all(|v| v.is_finite()));
    // Issue 20: every number of the result is finite (the χ² was NaN, a null in the JSON).
    assert!(r.fit_chi2_per_dof.is_finite(), "{}", r.fit_chi2_per_dof);
    for t in crate::math::allan::TERMS {
        let e = r.fit.get(t);
        assert!(e.value.is_finite() && e.sigma.is_finite(), "{t:?}: {e:?}");
    }
}

#[test]
fn bad_input_is_reported_with_its_index() {
    let good = vec![0.0; 64];
    let mut bad = good.clone();
    bad[5] = f64::NAN;
    let o = AllanOptions::default();
    let e = analyze(&Phase::from_increments(&bad), 0.01, &o).expect_err("NaN");
    assert!(matches!(e, AllanError::NonFinite { index: 5, .. }), "{e}");
    let e = analyze(&Phase::from_increments(&good[..3]), 0.01, &o).expect_err("short");
    assert!(matches!(e, AllanError::TooFewSamples { got: 3, .. }), "{e}");
    assert!(matches!(analyze(&Phase::from_increments(&good), 0.0, &o), Err(AllanError::BadTau0(_))));
    let o2 = AllanOptions { ci_sigma: 0.0, ..o };
    assert!(matches!(analyze(&Phase::from_increments(&good), 0.01, &o2), Err(AllanError::BadOption(_))));
}
