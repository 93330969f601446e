//! Issue 32 on the real binary: a parked log read with no option at all navigates with what its
//! alignment estimated (drift within the Schuler model of the residual, not of the estimate); a
//! log without a calibration sequence is refused by `selfcal --log`, never estimated.

mod common;
use common::{rinscope, scratch, stderr};

/// A parked navigation-grade IMU (gyro bias 0, ARW 0.001 °/√h; accelerometer bias 2 mg, −1.5 mg,
/// 0.1 mg, 10 µg/√Hz), 100 Hz, 34° N; `seconds` long.
fn parked(seconds: f64) -> String {
    format!(
        "[scenario]\nname = \"parked\"\ntitle = \"t\"\nseed = 7\n[simulation]\nduration_s = {seconds}\nstep_hz = 100.0\n\
         [site]\nlatitude_deg = 34.0\n[vehicle]\nheading_deg = 30.0\npitch_deg = 1.0\nroll_deg = -1.5\n\
         [turntable]\n[[turntable.axis]]\nname = \"azimuth\"\naxis = \"z\"\n[scheme]\nkind = \"static\"\n\
         [imu]\nalgorithm = \"two-sample\"\n[imu.gyro]\nbias_deg_per_h = [0.0, 0.0, 0.0]\narw_deg_per_sqrt_h = 0.001\n\
         [imu.accel]\nbias_ug = [2000.0, -1500.0, 100.0]\nvrw_ug_per_sqrt_hz = 10.0\n[navigation]\nvertical = \"held\"\n"
    )
}

fn export(dir: &std::path::Path, seconds: f64) -> std::path::PathBuf {
    std::fs::write(dir.join("parked.toml"), parked(seconds)).expect("write");
    let log = dir.join("log");
    let out = rinscope()
        .args(["export-log", "--config", "parked.toml", "--format", "npy", "--out", "log"])
        .current_dir(dir)
        .output()
        .expect("runs");
    assert!(out.status.success(), "{}", stderr(&out));
    log
}

#[test]
fn a_parked_log_read_with_no_option_navigates_with_its_alignment_estimates() {
    let dir = scratch("issue32-parked");
    let log = export(&dir, 2100.0);
    let imu = std::fs::read_dir(&log)
        .expect("log")
        .flatten()
        .map(|e| e.path())
        .find(|p| p.file_stem().is_some_and(|s| s == "imu"))
        .expect("an imu file");
    let out = rinscope()
        .arg("replay")
        .arg("--imu")
        .arg(&imu)
        .args(["--position", "34", "0", "0", "--save", "r.rrd", "--summary-json", "s.json"])
        .current_dir(&dir)
        .output()
        .expect("runs");
    assert!(out.status.success(), "{}", stderr(&out));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("s.json")).expect("summary")).expect("json");
    let notes = s["notes"].to_string();
    assert!(notes.contains("the navigation removes the biases the alignment estimated"), "{notes}");
    let drift = s["navigation"]["final_radial_m"].as_f64().expect("navigated");
    let t = s["duration_s"].as_f64().expect("duration");
    // The Schuler model: a constant horizontal force error δf gives R (δf/g)(1 − cos ω_s t); a
    // constant rate error ε gives R ε (t − sin ω_s t / ω_s).
    let (r, g) = (6_371_000.0, 9.80665);
    let w = (g / r).sqrt();
    let force = |df: f64| r * (df / g) * (1.0 - (w * t).cos());
    let rate = |e: f64| r * e * (t - (w * t).sin() / w);
    let al = &s["alignment"];
    let horizontal = |key: &str, unit: f64| {
        let v: Vec<f64> = al[key].as_array().expect(key).iter().map(|x| x.as_f64().expect("number") * unit).collect();
        v[0].hypot(v[1])
    };
    let ug = 9.80665e-6;
    let deg_per_h = std::f64::consts::PI / 180.0 / 3600.0;
    // Of the estimate: what navigating without it would give.
    let of_estimate = force(horizontal("accel_bias_ug", ug));
    // Of the residual, each at 3σ: the accelerometer noise averaged over the 300 s window, the gyro
    // bias estimate's reported 1σ, the angle random walk's tilt over the run.
    let of_residual = force(3.0 * 10.0 * ug / 300f64.sqrt())
        + rate(3.0 * horizontal("gyro_bias_sigma_deg_per_h", deg_per_h))
        + r * 3.0 * 0.001 * std::f64::consts::PI / 180.0 / 60.0 * t.sqrt();
    eprintln!("drift {drift:.0} m in {t:.0} s; Schuler of the estimate {of_estimate:.0} m, of the residual ≤ {of_residual:.0} m");
    assert!(drift < of_residual, "{drift} m");
    assert!(drift < 0.3 * of_estimate, "{drift} m against the estimate's {of_estimate} m");
}

#[test]
fn a_log_without_a_calibration_sequence_is_refused_by_selfcal() {
    let dir = scratch("issue32-static");
    let log = export(&dir, 600.0);
    let out = rinscope()
        .args(["selfcal", "--log"])
        .arg(&log)
        .args(["--no-recording", "--json", "s.json"])
        .current_dir(&dir)
        .output()
        .expect("runs");
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("no calibration sequence") && err.contains("turned 0.0°"), "{err}");
    assert!(!dir.join("s.json").exists(), "an estimate was written");
}
