use std::sync::atomic::AtomicBool;

use nalgebra::{DMatrix, DVector, Vector3};

use crate::math::frames::Rot;

use super::estimate::exact_residual;
use super::*;
use crate::app::calibrate::{calibrate_scenario, collect, monte_carlo};
use crate::math::units::{ARCSEC_PER_RAD, RAD_PER_ARCSEC, RAD_PER_DEG};
use crate::scenario::{Params, presets};

/// The calibration preset (Jiang et al. 2017 Table 2 truth) with the IMU and encoder noise removed.
fn noise_free() -> Params {
    let mut p = presets::load("jiang2017-calibration").expect("preset");
    p.ins = None;
    for a in &mut p.table.truth.axes {
        a.encoder_noise_rad = 0.0;
    }
    p
}

fn arcsec(x: f64) -> f64 {
    x * ARCSEC_PER_RAD
}

#[test]
fn first_order_columns_are_the_closed_form_model() {
    // H·θ must equal the closed form of docs/closed-form.md (gimbal::first_order_phi_b, written
    // independently), for any parameters and angles: checked at 50 random-ish angle pairs.
    let p = noise_free();
    let set = ParamSet::new(&p.table.chain, Nuisance::None);
    let theta = [120.0, -75.0, 40.0, 310.0, -25.0].map(|x| x * RAD_PER_ARCSEC);
    let errors = set.errors(&theta, &TableErrors::zero(2));
    let n_from_b = Attitude { pitch_rad: 0.1, roll_rad: -0.2, heading_rad: 0.7 }.n_from_b();
    let nb = n_from_b.matrix();
    let mut h = [[0.0; MAX_TABLE]; 3];
    for i in 0..50 {
        let angles = [0.37 * i as f64, -1.13 * i as f64 + 0.2, 0.0];
        let s = Measurement { t_s: 0.0, n_from_s: Rot::identity(), shafts: p.table.chain.shaft_rotations(&angles) };
        set.table_rows(&p.table.chain, &nb, &s, &mut h);
        let ours = Vector3::from_fn(|r, _| (0..5).map(|j| h[r][j] * theta[j]).sum::<f64>());
        let closed = nb * p.table.chain.first_order_phi_b(&errors, &angles, &[0.0; 3]).v;
        assert!((ours - closed).norm() < 1e-15, "angles {angles:?}: {ours:?} vs {closed:?}");
    }
}

#[test]
fn the_filter_is_eq_33_in_information_form() {
    // Jiang et al. 2017 eq. 33 literally (x̂_k = x̂_{k−1} + P_k H R⁻¹ (z − H x̂_{k−1}),
    // P_k = (P_{k−1}⁻¹ + Hᵀ R⁻¹ H)⁻¹), run sample by sample on the first 2000 measurements, against
    // the information form the calibration uses: the same estimate to rounding.
    let mut p = presets::load("jiang2017-calibration").expect("preset");
    p.duration_s = 10.0;
    p.calibration.nuisance = Nuisance::None;
    let data = collect(&p, 5, &AtomicBool::new(false)).expect("data");
    let cal = calibrate(
        &p.table.chain,
        &p.table.compensation,
        &data,
        &p.calibration,
        History::Final,
        &AtomicBool::new(false),
    )
    .expect("calibration");
    let set = &cal.set;
    let (x0, s0) = set.prior(&p.calibration);
    let mut x = DVector::from_vec(x0);
    let mut pm = DMatrix::from_diagonal(&DVector::from_iterator(5, s0.iter().map(|s| s * s)));
    let nb = data.n_from_b.matrix();
    let before = p.table.chain.error_rotations(&set.without_estimated(&p.table.compensation));
    let mut h = [[0.0; MAX_TABLE]; 3];
    let Samples::Memory(samples) = &data.samples else { panic!("a 10 s test fits in memory") };
    for s in samples {
        set.table_rows(&p.table.chain, &nb, s, &mut h);
        let hm = DMatrix::from_fn(3, 5, |r, j| h[r][j]);
        let z = exact_residual(&p.table.chain, &before, s, &data.n_from_b.inverse());
        let z = DVector::from_column_slice(z.as_slice());
        // R of this sample: each encoder's noise about its shaft's axis (nav frame) + σ² I.
        let mut r = nalgebra::Matrix3::identity() * p.calibration.measurement_sigma_rad.powi(2);
        let mut m = nb;
        for (k, g) in p.table.chain.axes().iter().enumerate() {
            let u = m * g.axis;
            r += u * u.transpose() * p.table.truth.axes[k].encoder_noise_rad.powi(2);
            m *= s.shafts.0[k].to_rotation_matrix().into_inner();
        }
        let r_inv = DMatrix::from_fn(3, 3, |i, j| r.try_inverse().expect("R invertible")[(i, j)]);
        let p_inv = pm.clone().try_inverse().expect("invertible") + hm.transpose() * &r_inv * &hm;
        pm = p_inv.try_inverse().expect("invertible");
        x = &x + &pm * hm.transpose() * &r_inv * (z - &hm * &x);
    }
    for j in 0..5 {
        assert!((x[j] - cal.kf.theta[j]).abs() < 1e-6 * RAD_PER_ARCSEC, "state {j}: {} vs {}", x[j], cal.kf.theta[j]);
    }
}

#[test]
fn noise_free_data_give_the_true_parameters() {
    // No IMU error, no encoder noise, Jiang et al. 2017 Table 2 values. What the data determine — α1, φ1,
    // α2 cos φ2 and η_eff = η − α2 sin φ2 — the exact least squares recovers to 0.01″ (phase: 0.01″
    // of phase angle); the first-order filter is off by its neglected second-order terms.
    let p = noise_free();
    let data = collect(&p, 1, &AtomicBool::new(false)).expect("data");
    let cal = calibrate(
        &p.table.chain,
        &p.table.compensation,
        &data,
        &p.calibration,
        History::Final,
        &AtomicBool::new(false),
    )
    .expect("calibration");
    let report = report::build("t", &p.table.chain, &p.table.truth, &cal, &data, None);
    let row = |key: &str| {
        report.angles.iter().chain(&report.state).find(|r| r.key == key).unwrap_or_else(|| panic!("no row {key}"))
    };
    for key in ["inner.swing_half_angle", "outer.swing_cos", "inner.effective_non_orthogonality"] {
        let r = row(key);
        assert!(r.nls_error().abs() < 0.01, "{key}: LSQ error {}″", r.nls_error());
    }
    let phase = row("inner.swing_phase");
    assert!(phase.nls_error().abs() * 3600.0 < 0.01, "inner φ: {}″ of phase", phase.nls_error() * 3600.0);
    // The filter's error is the second-order model error: non-zero, below α1·α2 (0.87″).
    let kf_worst = report.state[..3].iter().map(|r| r.kf_error().abs()).fold(0.0, f64::max);
    assert!(kf_worst > 0.05 && kf_worst < 0.87, "filter error {kf_worst}″");

    // Given η from an independent measurement (exactly), all five of the paper's parameters follow.
    let mut p = p;
    p.calibration.prior_eta_rad = p.table.truth.axes[1].non_orthogonality_rad;
    p.calibration.prior_eta_sigma_rad = 1e-9 * RAD_PER_ARCSEC;
    let cal = calibrate(
        &p.table.chain,
        &p.table.compensation,
        &data,
        &p.calibration,
        History::Final,
        &AtomicBool::new(false),
    )
    .expect("calibration");
    let report = report::build("t", &p.table.chain, &p.table.truth, &cal, &data, None);
    assert!(report.unobservable.iter().all(|u| u.resolved_by_prior), "{:?}", report.unobservable);
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    for r in &report.angles {
        let err = if r.unit == "deg" { r.nls_error() * 3600.0 } else { r.nls_error() };
        assert!(err.abs() < 0.01, "{}: error {err}″", r.key);
    }
}

#[test]
fn outer_swing_and_eta_are_one_rotation_and_the_report_says_so() {
    // The exact chain: the outer rotor's swing component about x and the inner axis' tilt η sit
    // side by side in gimbal 1 (docs/calibration.md), so swapping one for the other changes the
    // IMU attitude by the commutator term only (second order: ½·η·α2 cos φ2 ≈ 0.03″ here).
    let p = noise_free();
    let set = ParamSet::new(&p.table.chain, Nuisance::None);
    let mut a = set.values(&p.table.truth);
    let mut b = a.clone();
    let shift = 15.0 * RAD_PER_ARCSEC;
    a[3] += shift; // outer α sin φ
    b[4] -= shift; // inner η, the opposite way: η_eff unchanged
    let (ea, eb) = (set.errors(&a, &p.table.truth), set.errors(&b, &p.table.truth));
    let (ra, rb) = (p.table.chain.error_rotations(&ea), p.table.chain.error_rotations(&eb));
    for i in 0..40 {
        let angles = [0.3 * i as f64, 0.71 * i as f64, 0.0];
        let d = (p.table.chain.b_from_s(&ra, &angles).quaternion().inverse()
            * p.table.chain.b_from_s(&rb, &angles).quaternion())
        .angle();
        assert!(arcsec(d) < 0.05, "difference {}″", arcsec(d));
    }
    // And the calibration reports exactly that direction as unobservable, with η_eff determined.
    let data = collect(&p, 1, &AtomicBool::new(false)).expect("data");
    let cal = calibrate(
        &p.table.chain,
        &p.table.compensation,
        &data,
        &p.calibration,
        History::Final,
        &AtomicBool::new(false),
    )
    .expect("calibration");
    let report = report::build("t", &p.table.chain, &p.table.truth, &cal, &data, None);
    assert_eq!(report.unobservable.len(), 1, "{:?}", report.unobservable);
    let dir = &report.unobservable[0].direction;
    let keys: Vec<&str> = dir.iter().map(|(k, _)| k.as_str()).collect();
    assert_eq!(keys, ["outer.swing_sin", "inner.non_orthogonality"]);
    assert!((dir[0].1 - dir[1].1).abs() < 1e-3 && (dir[0].1 - 0.707).abs() < 1e-3, "{dir:?}");
    let (name, v) = report.unobservable[0].determined.clone().expect("a determined combination");
    assert!(name.contains("outer α·sin φ") && name.contains("inner η"), "{name}");
    // outer α sin φ − η = 10.47″ − 20″.
    let expected = arcsec(set.values(&p.table.truth)[3] - set.values(&p.table.truth)[4]);
    assert!((v.value.abs() - expected.abs()).abs() < 0.01, "{} vs {expected}", v.value);
    assert!(report.warnings.iter().any(|w| w.contains("not observable")), "{:?}", report.warnings);
    for key in ["outer.swing_half_angle", "outer.swing_phase", "inner.non_orthogonality"] {
        let r = report.angles.iter().find(|r| r.key == key).expect("row");
        assert!(!r.flag.is_empty(), "{key} must be flagged");
    }
}

#[test]
fn phase_and_eq_34_warnings_trigger_where_they_should() {
    // φ1 = 90°: x1 = α1 cos φ1 = 0, so Jiang et al. 2017 eq. 34's η = atan(x4/x1) is undefined → warning.
    // α1 = 0.02″ under 12″ encoder noise: the inner phase is undefined → warning.
    let mut p = presets::load("jiang2017-calibration").expect("preset");
    p.ins = None;
    p.duration_s = 60.0;
    p.table.truth.axes[1].swing_phase_rad = 90.0 * RAD_PER_DEG;
    let data = collect(&p, 3, &AtomicBool::new(false)).expect("data");
    let cal = calibrate(
        &p.table.chain,
        &p.table.compensation,
        &data,
        &p.calibration,
        History::Final,
        &AtomicBool::new(false),
    )
    .expect("calibration");
    let report = report::build("t", &p.table.chain, &p.table.truth, &cal, &data, None);
    assert!(report.warnings.iter().any(|w| w.contains("eq. 34")), "{:?}", report.warnings);
    assert!(!report.warnings.iter().any(|w| w.contains("phase is undefined")), "{:?}", report.warnings);

    p.table.truth.axes[1].swing_half_angle_rad = 0.02 * RAD_PER_ARCSEC;
    let data = collect(&p, 3, &AtomicBool::new(false)).expect("data");
    let cal = calibrate(
        &p.table.chain,
        &p.table.compensation,
        &data,
        &p.calibration,
        History::Final,
        &AtomicBool::new(false),
    )
    .expect("calibration");
    let report = report::build("t", &p.table.chain, &p.table.truth, &cal, &data, None);
    assert!(
        report.warnings.iter().any(|w| w.starts_with("inner: ") && w.contains("phase is undefined")),
        "{:?}",
        report.warnings
    );
    // A clearly non-zero α1 at φ1 = 1° raises neither.
    let p = presets::load("jiang2017-calibration").expect("preset");
    let data = collect(&p, 3, &AtomicBool::new(false)).expect("data");
    let cal = calibrate(
        &p.table.chain,
        &p.table.compensation,
        &data,
        &p.calibration,
        History::Final,
        &AtomicBool::new(false),
    )
    .expect("calibration");
    let report = report::build("t", &p.table.chain, &p.table.truth, &cal, &data, None);
    assert!(
        !report.warnings.iter().any(|w| w.contains("eq. 34") || w.contains("phase is undefined")),
        "{:?}",
        report.warnings
    );
}

#[test]
fn compensation_with_the_estimates_beats_the_papers_factors() {
    // Jiang et al. 2017's laboratory: peaks 1.6′ → 25.2″ (pitch), 1.86′ → 30.24″ (roll), 2.5′ → 49.32″
    // (heading). Under the paper's noise (Table 1 INS, 12″ encoders) rinscope's compensation with
    // its own estimates, on an independent run, must reduce each peak at least as much.
    let p = presets::load("jiang2017-calibration").expect("preset");
    let out = calibrate_scenario(&p, false, &AtomicBool::new(false)).expect("calibration");
    let c = out.report.compensation.expect("compensation");
    for (i, (before, after)) in report::PAPER_LAB.iter().enumerate() {
        let ours = c.before.peak_rad[i] / c.after_nls.peak_rad[i];
        assert!(ours >= before / after, "axis {i}: ×{ours:.2} vs the paper's ×{:.2}", before / after);
        // And it is the noise floor: the estimates do as well as the true values, within 2 %.
        assert!(c.after_nls.rms_rad[i] < 1.02 * c.with_truth.rms_rad[i], "axis {i}");
    }
}

#[test]
fn monte_carlo_statistics_are_stable_across_seeds() {
    // Two Monte Carlos of 40 runs with different seeds: for every identifiable quantity the
    // least-squares error has a mean within 4 standard errors of 0 and standard deviations that agree
    // within the sampling spread of 40 runs (ratio within 0.55..1.8: the 99.9 % range of an F(39, 39)
    // ratio of variances is 0.36..2.8, of deviations 0.6..1.7).
    let stop = AtomicBool::new(false);
    let mut p = presets::load("jiang2017-calibration").expect("preset");
    let a = monte_carlo(&p, 40, &|| {}, &stop).expect("mc");
    p.meta.seed = 99;
    let b = monte_carlo(&p, 40, &|| {}, &stop).expect("mc");
    assert_eq!(a.runs, 40);
    let mut checked = 0;
    for (ra, rb) in a.rows.iter().zip(&b.rows) {
        if !ra.identifiable || ra.label.contains("of phase") {
            continue;
        }
        for r in [ra, rb] {
            assert!(
                r.nls.mean.abs() < 4.0 * r.nls.std / 40f64.sqrt() + 0.01,
                "{}: mean {} ± {}",
                r.label,
                r.nls.mean,
                r.nls.std
            );
            // 12″ encoder noise over 20 000 samples: ~0.1″, never arcseconds.
            assert!(r.nls.std < 0.5, "{}: std {}", r.label, r.nls.std);
        }
        let ratio = ra.nls.std / rb.nls.std;
        assert!((0.55..1.8).contains(&ratio), "{}: std {} vs {}", ra.label, ra.nls.std, rb.nls.std);
        checked += 1;
    }
    assert!(checked >= 3, "{checked} quantities compared");
}

#[test]
fn a_moving_vehicle_is_refused() {
    let mut p = presets::load("jiang2017-calibration").expect("preset");
    let wobble = crate::model::motion::Wobble {
        angle: crate::model::motion::AngleKind::Roll,
        amplitude_rad: 0.01,
        omega_rad_per_s: 0.5,
        phase_rad: 0.0,
    };
    p.table.vehicle =
        crate::model::motion::VehicleMotion::new(Attitude::default(), vec![], vec![wobble]).expect("motion");
    assert!(matches!(collect(&p, 0, &AtomicBool::new(false)), Err(CalibError::VehicleMoves(_))));
}

#[test]
fn a_replayed_test_calibrates_exactly_as_one_in_memory() {
    // A test longer than IN_MEMORY_SAMPLES is generated again for each pass instead of kept: the
    // estimates must not depend on which (same samples, same order, same sums).
    let mut p = presets::load("jiang2017-calibration").expect("preset");
    p.duration_s = 20.0;
    let stop = AtomicBool::new(false);
    let memory = collect(&p, 4, &stop).expect("data");
    let Samples::Memory(v) = &memory.samples else { panic!("20 s fits in memory") };
    let (count, last_t_s, v) = (v.len(), v.last().map_or(0.0, |m| m.t_s), v.clone());
    let replay = move |sink: &mut dyn FnMut(&Measurement) -> bool| -> Result<(), CalibError> {
        for m in &v {
            if !sink(m) {
                break;
            }
        }
        Ok(())
    };
    let replayed =
        Data { samples: Samples::Replayed { replay: Box::new(replay), count, last_t_s }, ..memory.clone_header() };
    let a = calibrate(&p.table.chain, &p.table.compensation, &memory, &p.calibration, History::Snapshots(1.0), &stop)
        .expect("memory");
    let b = calibrate(&p.table.chain, &p.table.compensation, &replayed, &p.calibration, History::Snapshots(1.0), &stop)
        .expect("replayed");
    assert_eq!(a.nls.theta, b.nls.theta);
    assert_eq!(a.kf.theta, b.kf.theta);
    assert_eq!(a.history.len(), b.history.len());
    assert!(a.history.len() >= 19, "{} snapshots", a.history.len());
}

#[test]
fn a_trace_stays_bounded_and_spans_the_whole_test() {
    let mut t = Thinned::new(0.0);
    for i in 0..1_000_000 {
        t.push(f64::from(i) * 0.01, i);
    }
    assert!(t.rows.len() <= MAX_TRACE_ROWS && t.rows.len() > MAX_TRACE_ROWS / 4, "{} rows", t.rows.len());
    assert_eq!(t.rows[0], 0);
    assert!(*t.t_s.last().expect("rows") > 9_900.0, "reaches the end: {:?}", t.t_s.last());
    assert!(t.t_s.windows(2).all(|w| w[1] > w[0]));
}

#[test]
fn reported_sigmas_match_the_spread_over_repeated_tests() {
    // Issue 12: each identifiable state's reported 1σ must match the spread of its estimate over
    // repeated static tests (same table, new noise) within 20 %. 150 tests: the sampling spread of
    // a standard deviation is 1/√(2·149) = 5.8 %, so 20 % is 3.4 of it. The reported 1σ are
    // built from where the noise enters: the encoders about their axes (per sample), the INS's
    // random walk and unknown bias through the whole test (estimate::InsTerm).
    let stop = AtomicBool::new(false);
    let p = presets::load("jiang2017-calibration").expect("preset");
    let runs = 150u64;
    let results: Vec<(Vec<f64>, Vec<f64>, Vec<f64>)> = {
        use rayon::prelude::*;
        (0..runs)
            .into_par_iter()
            .map(|i| {
                let data = collect(&p, 1000 + i, &stop).expect("data");
                let cal = calibrate(&p.table.chain, &p.calibration_known, &data, &p.calibration, History::Final, &stop)
                    .expect("cal");
                let truth = cal.set.values(&p.table.truth);
                let err: Vec<f64> = cal.nls.theta.iter().zip(&truth).map(|(x, t)| x - t).collect();
                let sig: Vec<f64> = (0..cal.set.len()).map(|k| cal.nls.sigma(k)).collect();
                // η_eff: the combination the data determine, its 1σ as the report propagates it.
                let f = super::report::effective_eta(&p.table.chain, &cal.set, 1).expect("eta_eff");
                let extra = vec![f(&cal.nls.theta) - f(&truth), super::report::propagate(&cal.nls, &f, 1.0).sigma];
                (err, sig, extra)
            })
            .collect()
    };
    let cal = calibrate_scenario(&p, false, &stop).expect("cal");
    let n = runs as f64;
    let spread = |xs: Vec<f64>| {
        let m = xs.iter().sum::<f64>() / n;
        (xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    };
    let mut checked = Vec::new();
    for (k, param) in cal.cal.set.params.iter().enumerate() {
        let flag = &cal.report.state[k].flag;
        let s = spread(results.iter().map(|r| r.0[k]).collect());
        let reported = results.iter().map(|r| r.1[k]).sum::<f64>() / n;
        eprintln!(
            "{:<40} spread {:.4}″ reported {:.4}″ ratio {:.3} {flag}",
            param.key(&p.table.chain),
            arcsec(s),
            arcsec(reported),
            reported / s
        );
        if flag.is_empty() {
            checked.push((param.key(&p.table.chain), s, reported));
        }
    }
    let s = spread(results.iter().map(|r| r.2[0]).collect());
    let reported = results.iter().map(|r| r.2[1]).sum::<f64>() / n;
    eprintln!("{:<40} spread {:.4}″ reported {:.4}″ ratio {:.3}", "η_eff", arcsec(s), arcsec(reported), reported / s);
    checked.push(("η_eff".into(), s, reported));
    for (key, s, reported) in &checked {
        assert!(
            (reported / s - 1.0).abs() < 0.2,
            "{key}: reported 1σ {:.4}″, spread over {runs} tests {:.4}″",
            arcsec(*reported),
            arcsec(*s)
        );
    }
    assert!(checked.len() >= 5, "{} states checked", checked.len());
}
