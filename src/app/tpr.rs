//! `rinscope tpr`: the Twice Position-fix Reset against the conventional reset, from one IMU stream:
//! the INS runs to the second fix, then forks; every branch sees the same samples after it
//! (docs/tpr.md; the estimator is `ins::reset`).

use std::sync::atomic::{AtomicBool, Ordering};

use crate::app::failure::Failure;
use crate::app::outputs::{RecordingName, RecordingRequest, check_output, finish, logged, write_json};
use crate::ins::pipeline::InsRun;
use crate::ins::reset::{
    BRANCHES, ResetSample, SweepRow, TprResult, azimuth_error_at_second_fix, azimuth_error_level_corrected,
    level_errors_from_velocity,
};
use crate::math::units::ARCSEC_PER_RAD;
use crate::model::earth::{Earth, normal_gravity};
use crate::record::sink::Saved;
use crate::scenario::Params;

/// Window over which the velocity's slow rate is read before a fix, s (hour-scale dynamics; long
/// enough to average the accelerometer noise: 20 µg/√Hz gives 0.17″ of tilt over 600 s).
const RATE_WINDOW_S: f64 = 600.0;

/// Why the comparison cannot run.
#[derive(Debug, thiserror::Error)]
pub enum TprError {
    /// Missing pieces.
    #[error("{0}")]
    Config(String),
}

/// The INS's heading error (arcsec) and east/north position errors (m, computed − true) at the
/// latest update.
fn errors(ins: &mut InsRun, t_s: f64) -> (f64, [f64; 2]) {
    let v = ins.view(t_s);
    let e = v.nav.unwrap_or_default();
    (v.errors[0].heading_rad * ARCSEC_PER_RAD, [e.east_m, e.north_m])
}

/// Whether the scenario can run the comparison: an INS with navigation and two position fixes.
pub fn check(params: &Params) -> Result<(), TprError> {
    if params.ins.as_ref().is_none_or(|i| i.navigation.is_none()) {
        return Err(TprError::Config(format!(
            "{}: needs an [imu] and a [navigation] section (see assets/scenarios/zheng2016-tpr.toml)",
            params.meta.name
        )));
    }
    if params.position_fix_s.len() < 2 {
        return Err(TprError::Config(format!(
            "{}: [position_fix] at_h needs two fixes (Zheng et al. 2016: at_h = [17.0, 21.0])",
            params.meta.name
        )));
    }
    Ok(())
}

/// Runs the scenario with its first two position fixes, conventional and TPR, sampling every `sample_s`.
pub fn compare_resets(params: &Params, sample_s: f64, stop: &AtomicBool) -> Result<TprResult, TprError> {
    let started = std::time::Instant::now();
    check(params)?;
    let (t1, t2) = (params.position_fix_s[0], params.position_fix_s[1]);
    let Some(mut ins) = params.ins_run() else {
        return Err(TprError::Config(format!("{}: needs [imu] and [navigation]", params.meta.name)));
    };
    let damping = params.ins.as_ref().and_then(|i| i.navigation.as_ref()).map_or(0.0, |n| n.damping_per_s);
    let earth = Earth::at(params.site);
    let lat = earth.site.latitude_rad;
    let (rm, _) = Earth::radii(lat);
    let g = normal_gravity(lat, earth.site.height_m);
    // The level errors a resting INS's velocity reveals (its true velocity is zero).
    // The velocity's slow rate is read over the last `RATE_WINDOW_S` before each fix.
    let velocity = |ins: &InsRun| ins.nav_state().map_or([0.0; 2], |n| [n.v_n.x, n.v_n.y]);
    let level = |ins: &InsRun, earlier: [f64; 2]| {
        let v = velocity(ins);
        let v_dot = [(v[0] - earlier[0]) / RATE_WINDOW_S, (v[1] - earlier[1]) / RATE_WINDOW_S];
        level_errors_from_velocity(v, v_dot, damping, lat, g)
    };
    // The INS's true level errors (the test's reference), in the reset equations' sign: the
    // rotation from the true to the computed frame, φ = log(C·C_trueᵀ) — the opposite sign of
    // `[navigation] initial_error`'s C = (I − [φ×]) C_true (docs/tpr.md says so).
    let true_level = |ins: &mut InsRun, t: f64| {
        let v = ins.view(t);
        let imu_true = v.imu_true.unwrap_or(v.imu_ins); // view() always has it
        let phi = crate::math::rotvec::log((v.imu_ins * imu_true.inverse()).quaternion());
        [phi.x, phi.y]
    };
    let mut true_phi = [[0.0; 2]; 2];
    let mut v_before = [[0.0; 2]; 2];
    let mut v_before_taken = [false; 2];
    // One INS sample per interval of the run.
    let steps = params.timeline().intervals();
    let mut samples = Vec::new();
    let mut next = 0.0;
    let mut i = 0u64;
    let mut dlat = [0.0; 2];
    let mut phi1 = [0.0; 2];
    let mut fix1_done = false;
    let mut complete = true;
    // Up to the second fix: one INS, all branches identical.
    while i < steps {
        let s = ins.step();
        i += 1;
        if !s.updated {
            continue;
        }
        for (f, t) in [t1, t2].into_iter().enumerate() {
            if !v_before_taken[f] && s.t_s >= t - RATE_WINDOW_S {
                v_before[f] = velocity(&ins);
                v_before_taken[f] = true;
            }
        }
        if !fix1_done && s.t_s >= t1 {
            dlat[0] = errors(&mut ins, s.t_s).1[1];
            phi1 = level(&ins, v_before[0]);
            true_phi[0] = true_level(&mut ins, s.t_s);
            ins.core_mut().reset_position();
            fix1_done = true;
        }
        if s.t_s >= t2 {
            break;
        }
        if s.t_s >= next {
            next += sample_s;
            let (h, en) = errors(&mut ins, s.t_s);
            let r = en[0].hypot(en[1]);
            samples.push(ResetSample {
                t_s: s.t_s,
                heading_arcsec: [h; BRANCHES],
                radial_m: [r; BRANCHES],
                east_north_m: [[en[0]; BRANCHES], [en[1]; BRANCHES]],
            });
        }
        if i.is_multiple_of(200_000) && stop.load(Ordering::Relaxed) {
            complete = false;
            break;
        }
    }
    // The second fix: every branch resets the position; TPR also corrects the azimuth.
    let t_fix2 = params.timeline().t_s(i);
    let (heading2, [_, lat2]) = errors(&mut ins, t_fix2);
    dlat[1] = lat2;
    let phi2 = level(&ins, v_before[1]);
    true_phi[1] = true_level(&mut ins, t_fix2);
    let dlat2 = lat2 / (rm + earth.site.height_m);
    let phi_u = azimuth_error_at_second_fix(0.0, dlat2, t2 - t1, lat);
    let phi_u_level = azimuth_error_level_corrected(phi1, phi2, dlat2, t2 - t1, lat);
    let mut branches: [InsRun; BRANCHES] = [ins.clone(), ins.clone(), ins];
    for b in &mut branches {
        b.core_mut().reset_position();
    }
    branches[1].core_mut().rotate_azimuth(-phi_u);
    branches[2].core_mut().rotate_azimuth(-phi_u_level);
    let remaining = steps.saturating_sub(i);
    let branch = |mut ins: InsRun| -> Vec<(f64, f64, [f64; 2])> {
        let mut out = Vec::new();
        let mut next = next;
        for j in 0..remaining {
            let s = ins.step();
            if s.updated && s.t_s >= next {
                next += sample_s;
                let (h, en) = errors(&mut ins, s.t_s);
                out.push((s.t_s, h, en));
            }
            if j.is_multiple_of(200_000) && stop.load(Ordering::Relaxed) {
                break;
            }
        }
        out
    };
    let traces: Vec<Vec<(f64, f64, [f64; 2])>> = std::thread::scope(|scope| {
        let handles: Vec<_> = branches.into_iter().map(|b| scope.spawn(move || branch(b))).collect();
        handles.into_iter().map(|h| h.join().unwrap_or_default()).collect()
    });
    let n = traces.iter().map(Vec::len).min().unwrap_or(0);
    for k in 0..n {
        let at = |b: usize| traces[b][k];
        samples.push(ResetSample {
            t_s: at(0).0,
            heading_arcsec: std::array::from_fn(|b| at(b).1),
            radial_m: std::array::from_fn(|b| at(b).2[0].hypot(at(b).2[1])),
            east_north_m: [std::array::from_fn(|b| at(b).2[0]), std::array::from_fn(|b| at(b).2[1])],
        });
    }
    complete &= !stop.load(Ordering::Relaxed);
    let to_arcsec = |v: [f64; 2]| v.map(|x| x * ARCSEC_PER_RAD);
    Ok(TprResult {
        scenario: params.meta.name.clone(),
        fixes_s: [t1, t2],
        samples,
        latitude_error_at_fixes_m: dlat,
        // The heading error is −φ_U.
        tpr_heading_estimate_arcsec: -phi_u * ARCSEC_PER_RAD,
        level_heading_estimate_arcsec: -phi_u_level * ARCSEC_PER_RAD,
        level_errors_arcsec: [to_arcsec(phi1), to_arcsec(phi2)],
        true_level_errors_arcsec: true_phi.map(to_arcsec),
        heading_at_second_fix_arcsec: heading2,
        duration_s: params.duration_s,
        wall_s: started.elapsed().as_secs_f64(),
        complete,
        arw_rad_per_sqrt_s: params.ins.as_ref().map_or(0.0, |i| i.errors.gyro.noise.random_walk_si),
        latitude_rad: params.site.latitude_rad,
    })
}

/// Runs the comparison for `seeds` consecutive seeds from the scenario's, in parallel (rayon).
/// A realisation of the random walk decides much of the outcome (docs/tpr.md): this gives the
/// distribution a single run of the paper cannot.
pub fn sweep(params: &Params, seeds: u64, stop: &AtomicBool) -> Result<Vec<SweepRow>, TprError> {
    use rayon::prelude::*;
    // A stop ends the sweep at once: the seeds not yet begun are skipped (each would otherwise
    // set up its navigation before its first look at the flag).
    let rows: Result<Vec<SweepRow>, TprError> = (0..seeds)
        .into_par_iter()
        .filter(|_| !stop.load(Ordering::Relaxed))
        .map(|k| {
            let mut p = params.clone();
            p.meta.seed = params.meta.seed.wrapping_add(k);
            let r = compare_resets(&p, 600.0, stop)?;
            Ok(SweepRow {
                seed: p.meta.seed,
                heading_at_second_fix_arcsec: r.heading_at_second_fix_arcsec,
                tpr_heading_estimate_arcsec: r.tpr_heading_estimate_arcsec,
                level_heading_estimate_arcsec: r.level_heading_estimate_arcsec,
                peak_radial_m: r.peak_radial_after_m(),
                peak_heading_arcsec: r.peak_heading_after_arcsec(),
            })
        })
        .collect();
    rows
}

/// `rinscope tpr`: the scenario, where its outputs go, and how many seeds to sweep after it.
pub struct TprRequest {
    /// A scenario with an INS, navigation and two position fixes.
    pub params: Params,
    /// The recording's sinks.
    pub recording: RecordingRequest,
    /// `--json`: the comparison and the sampled traces.
    pub json: Option<std::path::PathBuf>,
    /// `--seeds N`: also this many seeds in parallel, summarised.
    pub seeds: Option<u64>,
}

/// What `tpr` reports.
pub struct TprReport {
    /// The comparison as a user reads it.
    pub text: String,
    /// The recording kept.
    pub saved: Saved,
    /// The seed sweep's table and its wall time, s.
    pub sweep: Option<(String, f64)>,
    /// Stopped early: the recording holds what was simulated until then.
    pub interrupted: bool,
}

/// `tpr`'s one owner: the outputs checked, the comparison, its recording and document, the sweep.
///
/// # Errors
/// A scenario without what the comparison needs, an output that cannot be written.
pub fn execute(req: &TprRequest, stop: &AtomicBool) -> Result<TprReport, Failure> {
    let params = &req.params;
    check_output("--json", req.json.as_deref())?;
    check(params).map_err(|e| Failure::input(format!("tpr: {e}")))?;
    let sinks =
        req.recording.open(RecordingName { name: &params.meta.name, kind: None, seed: Some(params.meta.seed) })?;
    errln!("rinscope: navigating {:.1} h (forking at the second fix)...", params.duration_s / 3600.0);
    let result = compare_resets(params, 60.0, stop).map_err(|e| Failure::input(format!("tpr: {e}")))?;
    let text = result.text();
    logged(crate::record::tpr::log(&sinks.stream(), params, &result, &text))?;
    let saved = finish(sinks)?;
    if let Some(path) = &req.json {
        write_json("--json", path, &result)?;
    }
    let mut sweep_table = None;
    if let (Some(n), true) = (req.seeds, result.complete) {
        errln!("rinscope: {n} seeds from {} in parallel...", params.meta.seed);
        let started = std::time::Instant::now();
        let rows = sweep(params, n, stop).map_err(|e| Failure::input(format!("tpr: {e}")))?;
        if !stop.load(Ordering::SeqCst) {
            sweep_table = Some((crate::ins::reset::sweep_text(&rows), started.elapsed().as_secs_f64()));
        }
    }
    Ok(TprReport { text, saved, sweep: sweep_table, interrupted: !result.complete || stop.load(Ordering::SeqCst) })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::presets;

    /// The preset with its text edited: `preset = "none"` removes every sensor error.
    fn preset_with(edits: &[(&str, &str)]) -> Params {
        let mut text = presets::text("zheng2016-tpr").expect("preset").to_owned();
        for (from, to) in edits {
            assert!(text.contains(from), "{from}");
            text = text.replacen(from, to, 1);
        }
        crate::scenario::parse(&text, "test").expect("valid")
    }

    #[test]
    fn without_stochastic_errors_tpr_removes_the_azimuth_error() {
        // Zheng et al. 2016 §4.3 without sensor noise (initial heading error 1′ only), at 25 Hz to keep the
        // test short. The paper's estimator assumes zero level errors (its assumption a); velocity
        // damping leaves ~1″ of tilt, so its estimate is within 15 % of the true heading error, not
        // exact. With the level errors read from the velocity the same equations leave no residual
        // azimuth error at the fix (within 2 % of it; docs/tpr.md). Conventional keeps all of it.
        let p = preset_with(&[("preset = \"zheng2016\"", "preset = \"none\""), ("step_hz = 100.0", "step_hz = 25.0")]);
        let r = compare_resets(&p, 600.0, &AtomicBool::new(false)).expect("runs");
        let at_fix = r.heading_at_second_fix_arcsec;
        assert!(at_fix.abs() > 3.0, "a deterministic azimuth error to correct: {at_fix}″");
        let rel = |estimate: f64| (estimate - at_fix).abs() / at_fix.abs();
        assert!(
            rel(r.tpr_heading_estimate_arcsec) < 0.15,
            "TPR estimate {}″ vs {at_fix}″",
            r.tpr_heading_estimate_arcsec
        );
        assert!(
            rel(r.level_heading_estimate_arcsec) < 0.02,
            "TPR + level estimate {}″ vs {at_fix}″",
            r.level_heading_estimate_arcsec
        );
        let first_after = r.samples.iter().find(|s| s.t_s > r.fixes_s[1]).expect("samples after the fix");
        let [conventional, tpr, level] = first_after.heading_arcsec;
        assert!((conventional - at_fix).abs() < 0.1, "conventional keeps it: {conventional}″");
        assert!(tpr.abs() < 0.15 * at_fix.abs(), "TPR's residual {tpr}″");
        assert!(level.abs() < 0.02 * at_fix.abs(), "TPR + level's residual {level}″");
        let [conv, tpr, level] = r.peak_radial_after_m();
        assert!(
            tpr < 0.3 * conv && level < 0.3 * conv,
            "radial: conventional {conv} m, TPR {tpr} m, TPR + level {level} m"
        );
        // The level errors read from the velocity against the INS's own tilts (the simulated truth,
        // not the velocity equation inverted): docs/tpr.md reports agreement to 0.01″.
        for (fix, (read, truth)) in r.level_errors_arcsec.iter().zip(&r.true_level_errors_arcsec).enumerate() {
            for axis in 0..2 {
                assert!(truth[axis].abs() > 0.1, "fix {fix}: a tilt to read ({truth:?}″)");
                assert!(
                    (read[axis] - truth[axis]).abs() < 0.03,
                    "fix {fix}, axis {axis}: read {read:?}″, true {truth:?}″"
                );
            }
        }
    }

    #[test]
    fn a_scenario_without_two_fixes_is_refused() {
        let p = preset_with(&[("at_h = [17.0, 21.0]", "at_h = [17.0]")]);
        let e = compare_resets(&p, 600.0, &AtomicBool::new(false)).expect_err("one fix");
        assert!(e.to_string().contains("two fixes"), "{e}");
    }
}
