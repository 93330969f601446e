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
        .args(["export-log", "--config", "parked.toml", "--out", "log"])
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
    let (r, g): (f64, f64) = (6_371_000.0, 9.80665);
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
    let of_residual = force(3.0 * 10.0 * ug / 300_f64.sqrt())
        + rate(3.0 * horizontal("gyro_bias_sigma_deg_per_h", deg_per_h))
        + r * 3.0 * 0.001 * std::f64::consts::PI / 180.0 / 60.0 * t.sqrt();
    eprintln!(
        "drift {drift:.0} m in {t:.0} s; Schuler of the estimate {of_estimate:.0} m, of the residual ≤ {of_residual:.0} m"
    );
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

/// The compensation document of the simulation's truth as `selfcal` reports it (its `truth`, in its
/// parameters' order): the IMU part (gyro bias, K_g row-major, accelerometer bias, K_a's upper
/// triangle) and the table part, the true table folded as the encoders see it (per axis the
/// constant rotation after the shaft as a swing cone, the encoder's scale and delay; what folds into
/// them stated as zero), both in the accelerometer triad's frame — the frame of the estimates.
fn truth_document(selfcal: &serde_json::Value) -> String {
    let t: Vec<f64> = selfcal["truth"].as_array().expect("truth").iter().map(|x| x.as_f64().expect("number")).collect();
    let names: Vec<&str> =
        selfcal["parameters"].as_array().expect("names").iter().map(|n| n.as_str().expect("name")).collect();
    let at = |name: &str| t[names.iter().position(|n| *n == name).expect(name)];
    let deg_per_h = std::f64::consts::PI / 180.0 / 3600.0;
    let (ug, arcsec) = (9.80665e-6, std::f64::consts::PI / 180.0 / 3600.0);
    let kg: Vec<Vec<f64>> = (0..3).map(|i| (0..3).map(|j| t[3 + 3 * i + j] * 1e6).collect()).collect();
    let mut ka = vec![vec![0.0; 3]; 3];
    for (u, (i, j)) in [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)].into_iter().enumerate() {
        ka[i][j] = t[15 + u] * 1e6;
    }
    // The outer axis is y (its swing's directions z, x), the inner z (x, y).
    let axis = |name: &str, e1: &str, e2: &str| {
        let (x, y) = (at(&format!("{name}.swing_{e1}")), at(&format!("{name}.swing_{e2}")));
        serde_json::json!({
            "swing_half_angle_arcsec": x.hypot(y) / arcsec,
            "swing_phase_deg": y.atan2(x).to_degrees(),
            "encoder_scale_ppm": at(&format!("{name}.encoder_scale")) * 1e6,
            "encoder_delay_ms": at(&format!("{name}.encoder_delay")) * 1e3,
        })
    };
    let mut inner = axis("inner", "x", "y");
    inner["non_orthogonality_arcsec"] = serde_json::json!(0.0);
    inner["encoder_offset_arcsec"] = serde_json::json!(0.0);
    serde_json::json!({
        "estimated_compensation": {
            "enabled": true, "imu_mount_x_arcsec": 0.0, "imu_mount_y_arcsec": 0.0, "imu_mount_z_arcsec": 0.0,
            "axis": { "outer": axis("outer", "z", "x"), "inner": inner },
        },
        "estimated_imu_compensation": {
            "frame": selfcal["estimated_imu_compensation"]["frame"],
            "gyro_bias_deg_per_h": (0..3).map(|i| t[i] / deg_per_h).collect::<Vec<_>>(),
            "gyro_gain_ppm": kg,
            "accel_bias_ug": (0..3).map(|i| t[12 + i] / ug).collect::<Vec<_>>(),
            "accel_gain_ppm": ka,
        },
    })
    .to_string()
}

#[test]
fn the_imu_calibrated_by_selfcal_is_compensated_in_a_replay_as_well_as_by_the_truth() {
    let dir = scratch("issue32-compensation");
    // 1. Self-calibration of the preset's IMU (its built-in sequence).
    let out = rinscope()
        .args(["selfcal", "--navigate-hours", "0", "--no-recording", "--json", "sc.json"])
        .current_dir(&dir)
        .output()
        .expect("runs");
    assert!(out.status.success(), "{}", stderr(&out));
    let sc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("sc.json")).expect("json")).expect("json");
    assert!(sc["estimated_imu_compensation"]["gyro_gain_ppm"].is_array(), "{sc}");
    std::fs::write(dir.join("truth.json"), truth_document(&sc)).expect("write");
    // 2. The same IMU (same preset, same seed) on the table indexing through the preset's
    //    8-position scheme, repeated, 30 minutes, as a log set.
    let preset =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenarios/selfcal-nav-grade.toml"))
            .expect("preset");
    let scenario =
        preset.replace("duration_s = 5400.0", "duration_s = 1800.0").replace("repeat = false", "repeat = true")
            + "\n[navigation]\nvertical = \"held\"\n";
    std::fs::write(dir.join("rot.toml"), scenario).expect("write");
    let out = rinscope()
        .args(["export-log", "--config", "rot.toml", "--format", "npy", "--out", "log"])
        .current_dir(&dir)
        .output()
        .expect("runs");
    assert!(out.status.success(), "{}", stderr(&out));
    // 3. Replayed with no IMU compensation, the estimates', the truth's.
    let replay = |document: Option<&str>| {
        let mut cmd = rinscope();
        cmd.args(["replay", "log", "--save", "r.rrd", "--summary-json", "s.json"]).current_dir(&dir);
        if let Some(d) = document {
            cmd.args(["--compensation", d]);
        }
        let out = cmd.output().expect("runs");
        assert!(out.status.success(), "{}", stderr(&out));
        let s: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("s.json")).expect("json")).expect("json");
        let heading = s["attitude_error_arcsec"]["compensated"]["heading"]["rms_arcsec"].as_f64().expect("heading");
        let drift = s["navigation"]["peak_radial_m"].as_f64().expect("navigated");
        (heading, drift, s["notes"].to_string())
    };
    // The whole RINS uncompensated: no IMU compensation and the nominal table (the log's table
    // description compensates with the table's true errors, which is the "true" table part).
    std::fs::write(dir.join("nothing.json"), r#"{"estimated_compensation": {"enabled": false}}"#).expect("write");
    let nothing = replay(Some("nothing.json"));
    let none = replay(None);
    let estimated = replay(Some("sc.json"));
    let truth = replay(Some("truth.json"));
    eprintln!(
        "heading RMS / peak drift: nothing {:.1}″ {:.0} m, IMU none {:.1}″ {:.0} m, estimated (IMU and table) {:.1}″ {:.0} m, truth {:.1}″ {:.0} m",
        nothing.0, nothing.1, none.0, none.1, estimated.0, estimated.1, truth.0, truth.1
    );
    assert!(estimated.2.contains("the IMU is compensated with sc.json's estimates"), "{}", estimated.2);
    // The table's part: selfcal's folded table (sc.json's estimated_compensation) demodulates as
    // well as the table's true errors do — against the nominal table, whose 600″ swing alone puts
    // arcminutes into the heading.
    assert!(sc["estimated_compensation"]["axis"]["inner"]["encoder_scale_ppm"].is_number(), "{sc}");
    assert!(estimated.0 < 0.1 * nothing.0, "{estimated:?} against the nominal table {nothing:?}");
    // The estimates' 1σ are a few per cent of the errors (sc.json): compensated with them, the
    // replay is the truth-compensated one within the noise, and far from the uncompensated one.
    assert!(estimated.0 < 0.5 * none.0 && estimated.1 < 0.6 * none.1, "{estimated:?} against {none:?}");
    assert!(estimated.0 < 1.2 * truth.0 && estimated.1 < 1.2 * truth.1, "{estimated:?} against {truth:?}");
    // A document with an impossible number is refused, naming the key, before anything runs.
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("truth.json")).expect("truth")).expect("json");
    doc["estimated_imu_compensation"]["gyro_gain_ppm"][1][2] = serde_json::json!(1e9);
    std::fs::write(dir.join("bad.json"), doc.to_string()).expect("write");
    let out = rinscope()
        .args(["replay", "log", "--save", "b.rrd", "--compensation", "bad.json"])
        .current_dir(&dir)
        .output()
        .expect("runs");
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("estimated_imu_compensation.gyro_gain_ppm[1][2]") && err.contains("1e9"), "{err}");
    assert!(!dir.join("b.rrd").exists(), "a recording of a refused replay");
}
