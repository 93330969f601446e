//! Tests of the IEEE generator, most of them through the Allan analysis (`math::allan`).

use super::*;
use crate::math::allan::{AllanOptions, AllanReport, FLICKER_FLOOR, Phase, allan_curve, analyze};
use crate::math::units::{
    RAD_PER_ARCSEC, RAD_PER_S_PER_DEG_PER_H, RAD_PER_S_PER_SQRT_S_PER_DEG_PER_H_PER_SQRT_H,
    RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H,
};

const TAU0_S: f64 = 0.005;

fn rel(got: f64, want: f64) -> f64 {
    (got / want - 1.0).abs()
}

/// Axis-x error log (output − truth) of `n` samples, truth(k) on axis x.
fn error_log(terms: &IeeeTerms, seed: u64, n: usize, mut truth: impl FnMut(usize) -> f64) -> Phase {
    let mut g = TriadNoise::new(terms, TAU0_S, seed, 1);
    let mut p = Phase::with_capacity(n);
    for k in 0..n {
        let t = truth(k);
        p.push(g.apply(Vector3::new(t, 0.0, 0.0))[0] - t);
    }
    p
}

/// Every point of the curve within `z` relative sigmas of `model` (1σ = 1/√(2·EDF), the χ²
/// scatter of an Allan variance with EDF degrees of freedom, halved for the deviation).
fn assert_follows(r: &AllanReport, z: f64, model: impl Fn(f64) -> f64, what: &str) {
    for j in 0..r.taus_s.len() {
        let want = model(r.taus_s[j]);
        let band = z / (2.0 * r.edf[j]).sqrt();
        assert!(
            rel(r.adev_si[j], want) < band,
            "{what}: tau {} s: ADEV/model = {:.4}, band ±{band:.4}",
            r.taus_s[j],
            r.adev_si[j] / want
        );
    }
}

#[test]
fn same_seed_same_output_other_seed_and_other_axis_differ() {
    let terms = IeeeTerms {
        quantization_si: 1e-7 / 12f64.sqrt(),
        random_walk_si: 1e-5,
        bias_instability_si: 1e-5,
        rate_random_walk_si: 1e-6,
        rate_ramp_si: 1e-7,
        saturation_si: Some(10.0),
        ..IeeeTerms::default()
    };
    let run = |seed: u64| -> Vec<Vector3<f64>> {
        let mut g = TriadNoise::new(&terms, TAU0_S, seed, 1);
        (0..10_000).map(|_| g.apply(Vector3::new(1e-5, -2e-5, 5e-6))).collect()
    };
    let (a, b) = (run(42), run(42));
    assert!(a.iter().zip(&b).all(|(x, y)| x.iter().zip(y.iter()).all(|(p, q)| p.to_bits() == q.to_bits())));
    let c = run(43);
    assert!(a.iter().zip(&c).filter(|(x, y)| x[0] != y[0]).count() > 9_000);
    // Axes draw from their own streams: same parameters, other numbers.
    assert!(a.iter().filter(|x| x[0] - 1e-5 != x[2] - 5e-6).count() > 9_000);
}

#[test]
fn quantization_carry_never_drifts_over_a_million_samples() {
    // Golden: pulse counting with carry, Σ output = Σ input − carry and |carry| ≤ q/2 (rounding to
    // the nearest pulse) at every sample; the truth summed by Neumaier's compensated sum.
    let terms = IeeeTerms { quantization_si: 1e-6 / 12f64.sqrt(), ..IeeeTerms::default() };
    let q = terms.pulse_weight_si();
    let mut g = TriadNoise::new(&terms, TAU0_S, 3, 1);
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let (mut sum, mut comp) = (0.0f64, 0.0f64);
    for k in 0..1_000_000 {
        let t = 3.7e-5 + 2e-5 * rng.random::<f64>() - if k % 7 == 0 { 4e-5 } else { 0.0 };
        g.apply(Vector3::new(t, 0.0, 0.0));
        let s = sum + t;
        comp += if sum.abs() >= t.abs() { (sum - s) + t } else { (t - s) + sum };
        sum = s;
        let out = g.pulse_counts()[0] as f64 * q;
        assert!((out - (sum + comp)).abs() <= 0.5 * q * (1.0 + 1e-6), "sample {k}");
    }
    assert!((g.carry_si()[0] - (sum + comp - g.pulse_counts()[0] as f64 * q)).abs() < 1e-6 * q);
}

#[test]
fn rate_random_walk_is_exactly_discretised() {
    // Golden: IEEE 952-1997 C.1.4, σ(τ) = K√(τ/3). At τ = τ0 the naive increment b_k·τ0 would give
    // K√(τ0/2), 22 % high; the first five points are within 1.5 % (EDF ≥ 1e5 there).
    let k = 1e-4;
    let terms = IeeeTerms { rate_random_walk_si: k, ..IeeeTerms::default() };
    let c = allan_curve(&error_log(&terms, 5, 1_000_000, |_| 0.0), TAU0_S, &AllanOptions::default()).expect("ok");
    for j in 0..5 {
        let want = k * (c.taus_s[j] / 3.0).sqrt();
        assert!(rel(c.avar_si[j].sqrt(), want) < 0.015, "m={} {}", c.m[j], c.avar_si[j].sqrt() / want);
    }
}

#[test]
fn gauss_markov_is_exactly_discretised() {
    // Golden: the Allan variance of a first-order Markov rate, IEEE 952-1997 C.1.6 (gauss_markov_avar),
    // for a correlation time of 100 samples and one below the sample interval.
    for (t_c, seed) in [(0.5, 1), (0.003, 2)] {
        let term = FlickerTerm { correlation_time_s: t_c, sigma_si: 1e-3 };
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut gm = GaussMarkov::new(term, 0.01, rng.sample(StandardNormal));
        let mut p = Phase::with_capacity(2_000_000);
        for _ in 0..2_000_000 {
            p.push(gm.step(rng.sample(StandardNormal), rng.sample(StandardNormal)));
        }
        let c = allan_curve(&p, 0.01, &AllanOptions::default()).expect("ok");
        for j in (0..c.m.len()).filter(|&j| c.m[j] <= 1024) {
            let want = gauss_markov_avar(1e-3, t_c, c.taus_s[j]).sqrt();
            assert!(rel(c.avar_si[j].sqrt(), want) < 0.05, "T={t_c} m={}: {}", c.m[j], c.avar_si[j].sqrt() / want);
        }
    }
}

#[test]
fn flicker_bank_floor_is_flat_analytically() {
    // Golden: IEEE 952-1997 C.1.3, flicker floor σ = B·√(2 ln2/π) ≈ 0.664 B.
    let b = 1e-6;
    for range in [[10.0, 1e4], [0.01, 1e4], [1.0, 100.0]] {
        let bank = flicker_bank(b, range);
        for i in 0..=50 {
            let tau = range[0] * (range[1] / range[0]).powf(f64::from(i) / 50.0);
            let avar: f64 = bank.iter().map(|t| gauss_markov_avar(t.sigma_si, t.correlation_time_s, tau)).sum();
            let ratio = avar.sqrt() / (FLICKER_FLOOR * b);
            assert!((0.983..=1.012).contains(&ratio), "range {range:?} tau {tau}: {ratio}");
        }
    }
    assert_eq!(flicker_bank(b, [1.0, 1e4]).len(), 7);
    assert!(flicker_bank(b, [10.0, 5.0]).is_empty());
}

#[test]
fn rate_ramp_is_exact_and_fitted() {
    // Golden: IEEE 952-1997 C.1.5, σ(τ) = Rτ/√2 (exact for a sampled parabola).
    let r = 1e-6;
    let terms = IeeeTerms { rate_ramp_si: r, ..IeeeTerms::default() };
    let rep = analyze(&error_log(&terms, 1, 100_000, |_| 0.0), TAU0_S, &AllanOptions::default()).expect("ok");
    for (t, a) in rep.taus_s.iter().zip(&rep.adev_si) {
        assert!(rel(*a, r * t / 2f64.sqrt()) < 1e-6, "tau {t}");
    }
    assert!(rel(rep.fit.r_si.value, r) < 1e-6);
    assert_eq!(rep.fit.significant_terms(), vec![NoiseTerm::RateRamp]);
}

#[test]
fn saturation_clips_the_rate_and_is_counted() {
    let terms = IeeeTerms { saturation_si: Some(1.0), ..IeeeTerms::default() };
    let mut g = TriadNoise::new(&terms, TAU0_S, 0, 1);
    let out = g.apply(Vector3::new(2.0 * TAU0_S, 0.5 * TAU0_S, -3.0 * TAU0_S));
    assert_eq!(out, Vector3::new(TAU0_S, 0.5 * TAU0_S, -TAU0_S));
    assert_eq!(g.saturation_counts(), [1, 0, 1]);
    assert!(g.apply(Vector3::new(f64::NAN, 0.0, 0.0))[0].is_nan());
}

/// The noise terms of the `static-imu-10h` preset's gyros (assets/scenarios/static-imu-10h.toml):
/// N = 0.02 °/√h, B = 2 °/h (floor flat over 0.1..10⁴ s), K = 30 °/h/√h. Each owns a decade:
/// N below 0.8 s ((N/0.664B)²), B 0.8..21 s, K above 21 s (3(0.664B/K)²).
pub(crate) fn preset_gyro() -> IeeeTerms {
    IeeeTerms {
        random_walk_si: 0.02 * RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H,
        bias_instability_si: 2.0 * RAD_PER_S_PER_DEG_PER_H,
        flicker_range_s: [0.1, 1e4],
        rate_random_walk_si: 30.0 * RAD_PER_S_PER_SQRT_S_PER_DEG_PER_H_PER_SQRT_H,
        ..IeeeTerms::default()
    }
}

#[test]
fn a_static_10h_log_gives_back_n_b_and_k() {
    // Golden: the configured coefficients, through the slope relations of IEEE 952-1997 C.1
    // (σ = N/√τ, 0.664·B, K√(τ/3)). Bands (docs/allan.md derives them from the EDF at the τ where
    // each term is read): N to 10 %, B to 25 %, K to 10 % of the truth; in a 40-seed study of this
    // configuration (seed_study_of_the_preset_fit) the fit's 1σ scatter is 0.03 % (N), 0.5 % (B), 2.8 % (K), worst
    // of 40 0.14 %, 1.7 %, 5.1 %, so a failure means a
    // broken generator or estimator, not bad luck. And every point of the curve lies within 4σ
    // (EDF) of the exact ADEV of what was configured (flicker bank included), the truth the viewer draws.
    let terms = preset_gyro();
    let r = analyze(&error_log(&terms, 1, 7_200_000, |_| 0.0), TAU0_S, &AllanOptions::default()).expect("ok");
    let f = r.fit;
    eprintln!(
        "static 10 h (seed 1): N/true {:.4} (±{:.4}), B/true {:.4} (±{:.4}), K/true {:.4} (±{:.4})",
        f.n_si.value / terms.random_walk_si,
        f.n_si.sigma / terms.random_walk_si,
        f.b_si.value / terms.bias_instability_si,
        f.b_si.sigma / terms.bias_instability_si,
        f.k_si.value / terms.rate_random_walk_si,
        f.k_si.sigma / terms.rate_random_walk_si
    );
    assert!(rel(f.n_si.value, terms.random_walk_si) < 0.10, "N {}", f.n_si.value / terms.random_walk_si);
    assert!(rel(f.b_si.value, terms.bias_instability_si) < 0.25, "B {}", f.b_si.value / terms.bias_instability_si);
    assert!(rel(f.k_si.value, terms.rate_random_walk_si) < 0.10, "K {}", f.k_si.value / terms.rate_random_walk_si);
    assert!(
        f.n_si.significant && f.b_si.significant && f.k_si.significant && !f.q_si.significant && !f.r_si.significant
    );
    assert_follows(&r, 4.0, |tau| terms.model_avar(tau).sqrt(), "static 10 h");
}

#[test]
fn a_quantization_dominated_log_gives_back_q() {
    // Golden: IEEE 952-1997 C.1.1, σ(τ) = √3·Q/τ with Q = q/√12. RLG-like: 1″ pulses (Q = 0.289″),
    // N = 0.001 °/√h, 1 h at 200 Hz; quantization dominates below q²/(4N²) ≈ 70 s. The truth
    // (10 °/s plus white vibration of 3 pulses rms per sample) decorrelates the remainder
    // (E e^{2πiδ/q} = e^{−2π²·9} ≈ 0); a static truth without dither leaves a correlated
    // remainder instead, not √3Q/τ (docs/allan.md). Q and N to 10 %, the curve within 4σ of
    // √(3Q²/τ² + N²/τ) everywhere.
    let terms = IeeeTerms {
        quantization_si: RAD_PER_ARCSEC / 12f64.sqrt(),
        random_walk_si: 0.001 * RAD_PER_SQRT_S_PER_DEG_PER_SQRT_H,
        ..IeeeTerms::default()
    };
    let q = terms.pulse_weight_si();
    let mut rng = ChaCha8Rng::seed_from_u64(77);
    let rate = 10f64.to_radians() * TAU0_S;
    let r = analyze(
        &error_log(&terms, 1, 720_000, |_| rate + 3.0 * q * rng.sample::<f64, _>(StandardNormal)),
        TAU0_S,
        &AllanOptions::default(),
    )
    .expect("ok");
    eprintln!(
        "quantization: fitted Q/true {:.4} (±{:.4}), slope reading Q/true {:.4}, N/true {:.4}; √3Q/τ at τ0: ADEV/model {:.4}",
        r.fit.q_si.value / terms.quantization_si,
        r.fit.q_si.sigma / terms.quantization_si,
        r.slope.q_si.map_or(f64::NAN, |s| s.value_si / terms.quantization_si),
        r.fit.n_si.value / terms.random_walk_si,
        r.adev_si[0] / terms.model_avar(r.taus_s[0]).sqrt()
    );
    assert!(
        rel(r.fit.q_si.value, terms.quantization_si) < 0.10 && r.fit.q_si.significant,
        "Q {}",
        r.fit.q_si.value / terms.quantization_si
    );
    assert!(rel(r.slope.q_si.expect("reading").value_si, terms.quantization_si) < 0.10);
    assert!(rel(r.fit.n_si.value, terms.random_walk_si) < 0.10, "N {}", r.fit.n_si.value / terms.random_walk_si);
    assert_follows(&r, 4.0, |tau| terms.model_avar(tau).sqrt(), "quantization");
}

#[test]
#[ignore = "a 40-seed study of the preset's fit, ~2 min: cargo test --release -- --ignored seed_study --nocapture"]
fn seed_study_of_the_preset_fit() {
    // Where the scatter quoted in `a_static_10h_log_gives_back_n_b_and_k` comes from.
    let terms = preset_gyro();
    let truth = [terms.random_walk_si, terms.bias_instability_si, terms.rate_random_walk_si];
    let mut errs: Vec<[f64; 3]> = Vec::new();
    for seed in 100..140 {
        let r = analyze(&error_log(&terms, seed, 7_200_000, |_| 0.0), TAU0_S, &AllanOptions::default()).expect("ok");
        let e =
            [r.fit.n_si.value / truth[0] - 1.0, r.fit.b_si.value / truth[1] - 1.0, r.fit.k_si.value / truth[2] - 1.0];
        let s = [r.fit.n_si.sigma / truth[0], r.fit.b_si.sigma / truth[1], r.fit.k_si.sigma / truth[2]];
        eprintln!(
            "seed {seed}: N {:+.4} (±{:.4}) B {:+.4} (±{:.4}) K {:+.4} (±{:.4})",
            e[0], s[0], e[1], s[1], e[2], s[2]
        );
        errs.push(e);
    }
    for (i, name) in ["N", "B", "K"].iter().enumerate() {
        let n = errs.len() as f64;
        let mean = errs.iter().map(|e| e[i]).sum::<f64>() / n;
        let sd = (errs.iter().map(|e| (e[i] - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let worst = errs.iter().map(|e| e[i].abs()).fold(0.0, f64::max);
        eprintln!("{name}: mean {mean:+.4}, sd {sd:.4}, worst |error| {worst:.4}");
    }
}
