//! `rinscope selfcal`: the IMU's 21 errors and the table's (through its encoders) from its own
//! gimbals. The estimator never reads the truth (the truth is the IMU the scenario's seed draws
//! and the table's errors folded as the encoders see them, by the exact chain, compared
//! afterwards); golden figures are issue 23's accuracy targets for a navigation-grade IMU, issue
//! 32's for its table, and the statistics of unit normals (a reported 1σ is honest when the errors
//! divided by it have unit spread).

use std::sync::atomic::AtomicBool;

use rinscope::app::selfcal::{SequenceChoice, monte_carlo, run_one, setup, target};
use rinscope::calib::selfcal::{N_PARAMS, ParamKind, Sequence, observability};
use rinscope::scenario::presets;

fn nav_grade(s: Sequence) -> rinscope::app::selfcal::Setup {
    setup(&presets::load("selfcal-nav-grade").expect("preset"), SequenceChoice::BuiltIn(s), true).expect("setup")
}

#[test]
fn every_error_is_recovered_within_its_sigma_and_the_targets_are_met() {
    let stop = AtomicBool::new(false);
    for seq in [Sequence::DualAxis29, Sequence::Positions19] {
        let s = nav_grade(seq);
        assert!(s.samples as f64 * s.config.h <= 2.0 * 3600.0, "at most 2 h");
        let o = run_one(&s, 2024, false, &stop).expect("run");
        let truth = o.all_truth(&s);
        let (names, params, sigmas, priors) =
            (o.estimate.names(), o.estimate.all_params(), o.estimate.all_sigma(), o.estimate.all_prior());
        // The IMU's 21 and the table's 8: a swing-fold pair, an encoder scale and delay per axis.
        assert_eq!(names.len(), N_PARAMS + 8, "{names:?}");
        for k in 0..names.len() {
            let (kind, name) = (ParamKind::of(k), &names[k]);
            let (unit, per_si) = kind.unit();
            let z = (params[k] - truth[k]) / sigmas[k];
            // Within 3σ, as issue 23 asks (a deterministic seed: its largest is 2.3σ).
            assert!(z.abs() < 3.0, "{}: {name} off by {z:.2}σ", s.sequence);
            let sigma = sigmas[k] * per_si;
            assert!(
                sigma <= target(kind),
                "{}: {name} 1σ {sigma:.4} {unit} misses the target {} {unit}",
                s.sequence,
                target(kind)
            );
            // Not a prior that barely moved: at least thirtyfold better (priors are 300 ppm, 300″,
            // 0.1°/h, 1 mg; the table's 600″, 1000 ppm, 10 ms).
            assert!(sigmas[k] < priors[k] / 30.0, "{name}");
        }
        // Where the estimated table puts the IMU (what the recording draws beside the true one):
        // within 1″ of the true table's place at every second of the sequence's last 10 minutes
        // (its states' 1σ are 0.06-0.11″ and 0.09-0.11 ppm of a half turn: 0.06″; 1″ is over 3σ of
        // their sum), where the nominal table is off by the swings' hundreds of arcseconds.
        let table = s.table_states.as_ref().expect("a table");
        let (reference, estimated) = (&truth[N_PARAMS..], &params[N_PARAMS..]);
        let end = o.shafts.last().expect("encoders").t_s;
        let late: Vec<_> = o.shafts.iter().filter(|x| x.t_s > end - 600.0).collect();
        assert!(late.len() > 500, "{} samples", late.len());
        let arcsec = |v: nalgebra::Vector3<f64>| v.norm() * 180.0 / std::f64::consts::PI * 3600.0;
        let worst = late.iter().map(|x| arcsec(table.states.offset(reference, estimated, x))).fold(0.0, f64::max);
        let nominal = late.iter().map(|x| arcsec(table.states.offset(reference, &[0.0; 8], x))).fold(0.0, f64::max);
        assert!(
            worst < 1.0 && nominal > 100.0,
            "{}: estimated table {worst:.2}″, nominal {nominal:.0}″ off",
            s.sequence
        );
        eprintln!(
            "{}: where the table puts the IMU, last 10 min: estimated {worst:.2}″, nominal {nominal:.0}″ off",
            s.sequence
        );
    }
}

#[test]
fn the_reported_sigma_matches_the_spread_over_random_imus() {
    let s = nav_grade(Sequence::DualAxis29);
    let runs = 30;
    let mc = monte_carlo(&s, runs, 500, &AtomicBool::new(false)).expect("mc");
    // The RMS of 30 normalised errors estimates 1 to ±13 % (1σ, 1/√60). 29 parameters tested at
    // once: at 3σ each (±40 %) one of them falls outside by chance 8 % of the time (29 × 0.27 %),
    // at 3.5σ (±45 %) 1.3 % — the band is 3.5σ (this seed's ba_z is 0.59; in 100 runs it is 1.01).
    // The pooled 29 × 30 to ±2.4 % (±9 % at 3σ, kept from the IMU's 21: the parameters are not
    // independent); the reported 1σ is nearly the same in every run. The IMU's and the table's.
    let n = mc.spread.len();
    assert_eq!(n, N_PARAMS + 8);
    let names = rinscope::calib::selfcal::names_with(s.table_states.as_ref().map(|t| &t.states));
    let mut pooled = 0.0;
    for k in 0..n {
        let rms = (mc.spread[k].powi(2) * (runs as f64 - 1.0) / runs as f64 + mc.mean_error[k].powi(2)).sqrt();
        let ratio = rms / mc.reported_sigma[k];
        assert!((0.55..=1.45).contains(&ratio), "{}: errors' RMS over reported 1σ = {ratio:.2}", names[k]);
        pooled += ratio * ratio;
    }
    let pooled = (pooled / n as f64).sqrt();
    assert!((0.91..=1.09).contains(&pooled), "pooled RMS of normalised errors {pooled:.3}");
}

#[test]
fn an_azimuth_only_sequence_names_what_it_cannot_see_before_it_runs() {
    let s = nav_grade(Sequence::AzimuthOnly);
    let plan = observability(&run_one(&s, 1, true, &AtomicBool::new(false)).expect("plan").estimate);
    // Turning about a vertical z, the accelerometers see gravity only along ±z: the horizontal
    // accelerometers' scale factors never get a signal; the outer shaft never turns, so nothing
    // of it is seen; and a z gyro's scale and the inner encoder's cannot be told apart (only the
    // gravity turning through the IMU would: here it never does).
    for name in ["Ka_xx", "Ka_yy", "Ka_xy", "outer.encoder_scale", "outer.encoder_delay", "outer.swing_x"] {
        assert!(plan.unobservable.iter().any(|n| n == name), "{name} should be reported: {:?}", plan.unobservable);
    }
    assert!(
        plan.aliased.iter().any(|a| a.starts_with("Kg_zz and inner.encoder_scale")),
        "the z gyro's scale and the inner encoder's: {:?}",
        plan.aliased
    );
    // Without the encoders the IMU's own navigation sees less: the x/y gyros' cross-axis terms
    // about z too get no signal (the encoders' attitude shows them as a tilt while z turns).
    let alone = setup(
        &presets::load("selfcal-nav-grade").expect("preset"),
        SequenceChoice::BuiltIn(Sequence::AzimuthOnly),
        false,
    )
    .expect("setup");
    let without = observability(&run_one(&alone, 1, true, &AtomicBool::new(false)).expect("plan").estimate);
    for name in ["Kg_zx", "Kg_zy"] {
        assert!(without.unobservable.iter().any(|n| n == name), "{name}: {:?}", without.unobservable);
        assert!(!plan.unobservable.iter().any(|n| n == name), "{name} is seen with the encoders");
    }
    for name in ["bg_x", "bg_y"] {
        assert!(
            !plan.unobservable.contains(&name.to_owned()) && !plan.weak.contains(&name.to_owned()),
            "{name} is seen at rest"
        );
    }
    assert!(
        plan.aliased.iter().any(|a| a.starts_with("ba_z and Ka_zz")),
        "z bias and scale factor cannot be told apart with z always up: {:?}",
        plan.aliased
    );
    // The good sequences leave nothing unobservable.
    for seq in [Sequence::DualAxis29, Sequence::Positions19] {
        let plan = observability(&run_one(&nav_grade(seq), 1, true, &AtomicBool::new(false)).expect("plan").estimate);
        assert!(
            plan.unobservable.is_empty() && plan.weak.is_empty() && plan.aliased.is_empty(),
            "{:?}",
            (plan.unobservable, plan.weak, plan.aliased)
        );
    }
    // The command says it before the table.
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_rinscope"))
        .args(["selfcal", "--sequence", "azimuth-only", "--plan"])
        .output()
        .expect("run");
    assert!(o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("not observable: ") && err.contains("Ka_xx") && err.contains("outer.encoder_scale"), "{err}");
}

#[test]
fn a_logged_sequence_gives_the_in_loop_result() {
    // The preset's own [scheme] (two moves after 300 s at rest), 960 s, exported as a log set and
    // calibrated from its files; the same scenario calibrated in the loop.
    let dir = std::env::temp_dir().join(format!("rinscope-selfcal-log-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("dir");
    let config = dir.join("short.toml");
    let text = presets::text("selfcal-nav-grade").expect("preset").replace("duration_s = 5400.0", "duration_s = 960.0");
    std::fs::write(&config, text).expect("config");
    let run = |args: &[&str]| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_rinscope")).args(args).output().expect("run");
        assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let (c, log, a, b) =
        (config.to_str().expect("utf-8"), dir.join("log"), dir.join("log.json"), dir.join("loop.json"));
    run(&["export-log", "--config", c, "--out", log.to_str().expect("utf-8"), "--format", "npy"]);
    // The log also holds the two samples the INS's filter pre-rolled before t = 0 (its first stamp
    // is −5 ms): its span starts where the loop's samples do.
    let manifest = log.join("log.toml");
    let text = std::fs::read_to_string(&manifest).expect("manifest").replacen("[log]\n", "[log]\nfrom_s = 0.004\n", 1);
    std::fs::write(&manifest, text).expect("manifest");
    run(&["selfcal", "--log", log.to_str().expect("utf-8"), "--no-recording", "--json", a.to_str().expect("utf-8")]);
    run(&[
        "selfcal",
        "--config",
        c,
        "--sequence",
        "scenario",
        "--no-recording",
        "--navigate-hours",
        "0",
        "--json",
        b.to_str().expect("utf-8"),
    ]);
    let read = |p: &std::path::Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(p).expect("json")).expect("valid")
    };
    let (from_log, in_loop) = (read(&a), read(&b));
    // A parameter the sequence does not separate has no estimate from the log (null, issue 32):
    // those the in-loop plan calls clearly unobservable (1σ still above 0.7 of its prior) have
    // none, those it sees (under 0.3) have one. Between, the line at 0.5 is crossed both ways by a
    // run's own linearization (Kg_zz, aliased with the inner encoder's scale: 0.39 from the log,
    // 0.50 in the loop, 0.62 in the plan).
    let v = |j: &serde_json::Value, k: &str| -> Vec<Option<f64>> {
        j[k].as_array().expect("array").iter().map(serde_json::Value::as_f64).collect()
    };
    let ratio: Vec<f64> = v(&in_loop["observability"], "ratio").into_iter().map(|r| r.expect("ratio")).collect();
    let (e1, s1) = (v(&from_log, "estimate"), v(&from_log, "sigma"));
    let names: Vec<String> =
        in_loop["parameters"].as_array().expect("names").iter().map(|n| n.as_str().expect("name").to_owned()).collect();
    assert_eq!(names.len(), N_PARAMS + 8, "the log's encoders measure the table too: {names:?}");
    assert_eq!(from_log["parameters"], in_loop["parameters"]);
    assert!(ratio.iter().any(|r| *r > 0.7), "the short sequence leaves some parameter unseen: {ratio:?}");
    for k in 0..names.len() {
        if ratio[k] > 0.7 {
            assert!(e1[k].is_none(), "{}: plan ratio {:.2}, log {:?}", names[k], ratio[k], e1[k]);
        }
        if ratio[k] < 0.3 {
            assert!(e1[k].is_some(), "{}: plan ratio {:.2}, no estimate from the log", names[k], ratio[k]);
        }
        assert_eq!(e1[k].is_none(), s1[k].is_none(), "{}", names[k]);
    }
    let known = |x: Vec<Option<f64>>| -> Vec<f64> { x.into_iter().map(|x| x.unwrap_or(f64::NAN)).collect() };
    let (e1, s1, e2, s2) = (known(e1), known(s1), known(v(&in_loop, "estimate")), known(v(&in_loop, "sigma")));
    // What the sequence sees well (1σ under a tenth of its prior), the log gives as the loop does.
    for k in (0..names.len()).filter(|&k| e1[k].is_finite() && ratio[k] < 0.1) {
        // The same samples and readings: to a tenth of a sigma (the files' decimal round trip
        // and the encoders' interpolation are not bit for bit).
        assert!((e1[k] - e2[k]).abs() < 0.1 * s2[k], "{}: log {} vs in loop {} (1σ {})", names[k], e1[k], e2[k], s2[k]);
        assert!((s1[k] / s2[k] - 1.0).abs() < 0.01, "{}: 1σ {} vs {}", names[k], s1[k], s2[k]);
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_estimates_buy_most_of_what_the_true_values_would() {
    // 6 h free-inertial (24 h in the command; the shape is the same, the test four times quicker).
    let p = presets::load("selfcal-nav-grade").expect("preset");
    let s = setup(&p, SequenceChoice::BuiltIn(Sequence::DualAxis29), true).expect("setup");
    let stop = AtomicBool::new(false);
    let o = run_one(&s, p.meta.seed, false, &stop).expect("run");
    let rows = rinscope::app::selfcal::navigation_comparison(&p, &o, 6.0, &stop).expect("navigate");
    let peak = |motion: &str, comp: &str| {
        rows.iter().find(|r| r.motion == motion && r.compensation == comp).expect("row").peak_radial_m
    };
    for motion in ["at rest", "16-position"] {
        let (none, est, truth) = (peak(motion, "none"), peak(motion, "estimated"), peak(motion, "true"));
        // The estimates leave 1σ-level residuals (0.001°/h, 0.2-0.6 ppm, 0.2″): between the
        // uncompensated IMU and the truth, and nearer the truth.
        assert!(est < none, "{motion}: estimated {est:.0} m vs none {none:.0} m");
        assert!(est < 3.0 * truth.max(1.0) + 100.0, "{motion}: estimated {est:.0} m vs true {truth:.0} m");
    }
    assert!(
        peak("at rest", "estimated") < peak("at rest", "none") / 4.0,
        "at rest the calibration is worth more than a factor 4"
    );
}
