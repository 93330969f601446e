//! `rinscope allan` end to end: the 10 h static preset read back within the bands on every
//! axis (through the simulation's whole IMU chain, the JSON a user gets), a log set analysed (one
//! with a table description, and a strapdown one without, written by the test, with `--export`),
//! and the new scenario keys refused clearly when misused.

mod common;
use common::{csv_table, rinscope, scratch, stderr};
use std::path::Path;

use serde_json::Value;

const PRESET: &str = include_str!("../assets/scenarios/static-imu-10h.toml");

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).expect("json written")).expect("valid json")
}

/// The fitted value of `key` on one channel and whether the fit found it.
fn fitted(ch: &Value, key: &str) -> (f64, bool) {
    let e = &ch["fitted"][key];
    (e["value"].as_f64().expect("value"), e["significant"].as_bool().expect("flag"))
}

fn configured(ch: &Value, key: &str) -> f64 {
    ch["configured"][key].as_f64().expect("configured value")
}

#[test]
fn the_10h_preset_gives_back_n_b_and_k_on_every_axis() {
    // Golden: the preset's configured N, B, K (assets/scenarios/static-imu-10h.toml), read back
    // through the IEEE 952/1293 slope relations. Bands from the issue, N and K within 10 %, B within
    // 25 %; docs/allan.md derives what each needs from the estimator's EDF (a 40-seed study of the
    // generator gives 1σ scatters of 0.03 % (N), 0.5 % (B), 2.8 % (K): K's band is 3.5σ, the others
    // far wider). Q and R are not configured and must not be found.
    let dir = scratch("preset");
    let (out, rec) = (dir.join("adev.json"), dir.join("allan.rrd"));
    let o = rinscope()
        .args(["allan", "--scenario", "static-imu-10h", "--json"])
        .arg(&out)
        .arg("--save")
        .arg(&rec)
        .output()
        .expect("run");
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("angle random walk") && text.contains("acceleration random walk"), "{text}");
    let j = json(&out);
    assert_eq!(j["samples"].as_u64(), Some(7_200_000));
    for (sensor, keys) in [
        ("gyro", ["n_deg_per_sqrt_h", "b_deg_per_h", "k_deg_per_h_per_sqrt_h", "q_arcsec", "r_deg_per_h2"]),
        ("accel", ["n_ug_per_sqrt_hz", "b_ug", "k_ug_per_sqrt_h", "q_mps", "r_ug_per_h"]),
    ] {
        let channels = j[sensor].as_array().expect("channels");
        assert_eq!(channels.len(), 3);
        for ch in channels {
            let axis = ch["axis"].as_str().unwrap_or("?");
            for (key, band) in [(keys[0], 0.10), (keys[1], 0.25), (keys[2], 0.10)] {
                let (value, found) = fitted(ch, key);
                let truth = configured(ch, key);
                assert!(
                    found && (value / truth - 1.0).abs() < band,
                    "{sensor} {axis} {key}: {value} vs {truth} (band {band})"
                );
            }
            for key in &keys[3..] {
                assert!(!fitted(ch, key).1, "{sensor} {axis}: {key} found but not configured");
            }
            // The curve, its bounds and the configured truth are all there, at the same cluster times.
            let taus = ch["tau_s"].as_array().expect("taus").len();
            let unit = if sensor == "gyro" { "deg_per_h" } else { "ug" };
            for k in ["adev", "adev_lower", "adev_upper", "configured_adev"] {
                assert_eq!(ch[format!("{k}_{unit}")].as_array().map(Vec::len), Some(taus), "{k}");
            }
        }
    }
    assert!(std::fs::metadata(&rec).map(|m| m.len()).unwrap_or(0) > 10_000, "a recording");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_log_set_is_analysed_from_its_files() {
    // 20 min of the preset written as a log set (csv) and read back: N, which 20 min measure to
    // ~0.15 % (white-rate EDF ~3.6e5 at τ0), within 5 % on all six channels; the configured values
    // come from the log set's table.toml, and the output says so.
    let dir = scratch("logset");
    let cfg = dir.join("short.toml");
    std::fs::write(&cfg, PRESET.replacen("duration_s = 36000.0", "duration_s = 1200.0", 1)).expect("config");
    let log = dir.join("log");
    let o = rinscope().args(["export-log", "--config"]).arg(&cfg).arg("--out").arg(&log).output().expect("export");
    assert!(o.status.success(), "{}", stderr(&o));
    let out = dir.join("adev.json");
    let o = rinscope().arg("allan").arg(&log).arg("--json").arg(&out).arg("--no-recording").output().expect("allan");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("table.toml"), "says where \"configured\" comes from");
    let j = json(&out);
    for (sensor, key) in [("gyro", "n_deg_per_sqrt_h"), ("accel", "n_ug_per_sqrt_hz")] {
        for ch in j[sensor].as_array().expect("channels") {
            let (value, found) = fitted(ch, key);
            let truth = configured(ch, key);
            assert!(found && (value / truth - 1.0).abs() < 0.05, "{sensor} {key}: {value} vs {truth}");
        }
    }
    // A gap of 0.5 s at 400 s (rows cut out of the csv), with the manifest's `gap_policy = "split"`:
    // the longest stretch without a gap (rows 80 101..240 002 of the 240 002 written: 400.5 s to 1200 s, 159 902
    // samples) is analysed, and the output says so.
    let imu = log.join("imu.csv");
    let text = std::fs::read_to_string(&imu).expect("imu.csv");
    let lines: Vec<&str> = text.lines().collect();
    let cut: Vec<&str> = lines[..80_001].iter().chain(&lines[80_101..]).copied().collect();
    std::fs::write(&imu, cut.join("\n") + "\n").expect("write");
    let manifest = std::fs::read_to_string(log.join("log.toml")).expect("manifest");
    std::fs::write(log.join("log.toml"), manifest.replacen("gap_policy = \"refuse\"", "gap_policy = \"split\"", 1))
        .expect("write");
    let o = rinscope().arg("allan").arg(&log).arg("--json").arg(&out).arg("--no-recording").output().expect("allan");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("1 gap(s): the longest stretch"),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    let j = json(&out);
    assert_eq!(j["samples"].as_u64(), Some(159_902), "{}", j["notes"]);
    std::fs::remove_dir_all(&dir).ok();
}

fn refused(args: &[&str], config: Option<(&str, &str)>, expected: &[&str]) {
    let dir = scratch("refused");
    let mut cmd = rinscope();
    cmd.args(args);
    if let Some((from, to)) = config {
        assert!(PRESET.contains(from), "the preset has `{from}`");
        let path = dir.join("edited.toml");
        std::fs::write(&path, PRESET.replacen(from, to, 1)).expect("write config");
        cmd.arg("--config").arg(&path);
    }
    let o = cmd.arg("--save").arg(dir.join("out.rrd")).output().expect("run");
    assert_eq!(o.status.code(), Some(2), "exit code; stderr: {}", stderr(&o));
    for e in expected {
        assert!(stderr(&o).contains(e), "stderr should mention `{e}`: {}", stderr(&o));
    }
    assert!(!dir.join("out.rrd").exists(), "no recording");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_requests_and_misused_keys_are_refused_by_name() {
    // Before this issue `bias_instability_deg_per_h` with `correlation_time_s` was a Gauss-Markov
    // bias; now it is IEEE's B, and the old spelling is pointed to the new one.
    let gm = ("bias_instability_deg_per_h = 2.0", "bias_instability_deg_per_h = 2.0\ncorrelation_time_s = 100.0");
    refused(&["allan"], Some(gm), &["imu.gyro.bias_instability_deg_per_h", "markov_sigma_deg_per_h"]);
    let both = (
        "arw_deg_per_sqrt_h = 0.02",
        "arw_deg_per_sqrt_h = 0.02\nquantization_arcsec = 0.1\npulse_weight_arcsec = 0.3",
    );
    refused(&["allan"], Some(both), &["imu.gyro.pulse_weight_arcsec", "not both"]);
    let range = (
        "bias_instability_range_s = [0.1, 10000.0]     # where",
        "bias_instability_range_s = [100.0, 10.0]     # where",
    );
    refused(&["allan"], Some(range), &["imu.gyro.bias_instability_range_s", "[100, 10] s"]);
    let ramp = ("# rate_ramp_deg_per_h2 = 0.0", "rate_ramp_deg_per_h2 = 1e9");
    refused(&["allan"], Some(ramp), &["imu.gyro.rate_ramp_deg_per_h2", "deg/h²"]);
    refused(&["allan", "--scenario", "jiang2017-dual-axis"], None, &["needs an [imu] section"]);
    refused(
        &["allan", "--scenario", "static-imu-10h", "--export", "x", "--export-format", "xls"],
        None,
        &["--export-format"],
    );
    refused(
        &["allan", "--scenario", "static-imu-10h", "--decimate", "0"],
        None,
        &["--decimate", "0: must be a whole number of samples, 1 ..= 1000000"],
    );
}

#[test]
fn a_strapdown_log_set_is_analysed_and_exported() {
    // A plain strapdown IMU's log set: log.toml with [imu] only (no table.toml, no start position:
    // the Allan deviation does not navigate), 150 s at 200 Hz of white noise written by the test —
    // gyros N = 0.05°/√h, accelerometers N = 40 µg/√Hz on gravity — analysed with --export: per
    // channel the curve (τ, ADEV, its bounds, the fit, EDF), per sensor the fitted coefficients.
    // White noise of density N sampled every τ0 has increments of σ = N·√τ0 (rad or m/s), and the
    // fit reads N back (30 000 samples: ~0.5 % 1σ) within 5 %.
    let dir = scratch("strapdown");
    let log = dir.join("log");
    std::fs::create_dir_all(&log).expect("log dir");
    let (rate_hz, n) = (200.0_f64, 30_000usize);
    let tau0 = 1.0 / rate_hz;
    let gyro_n = 0.05 * std::f64::consts::PI / 180.0 / 60.0; // 0.05 °/√h in rad/√s
    let accel_n = 40e-6 * 9.80665; // 40 µg/√Hz in m/s²/√Hz = m/s/√s
    // xorshift64* and Box-Muller: a fixed, dependency-free normal stream.
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut uniform = move || {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        ((state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    let mut normal = move || (-2.0 * uniform().ln()).sqrt() * (std::f64::consts::TAU * uniform()).cos();
    let mut csv = String::from("t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps\n");
    for k in 0..n {
        let g: Vec<f64> = (0..3).map(|_| gyro_n * tau0.sqrt() * normal()).collect();
        let a: Vec<f64> = (0..3).map(|_| accel_n * tau0.sqrt() * normal()).collect();
        csv.push_str(&format!(
            "{},{},{},{},{},{},{}\n",
            k as f64 * tau0,
            g[0],
            g[1],
            g[2],
            a[0],
            a[1],
            9.80665 * tau0 + a[2]
        ));
    }
    std::fs::write(log.join("imu.csv"), csv).expect("imu.csv");
    std::fs::write(log.join("log.toml"), "[log]\nname = \"strapdown-bench\"\n[imu]\nfile = \"imu.csv\"\nlayout = \"rinscope\"\nkind = \"increments\"\nrate_hz = 200.0\n").expect("log.toml");
    let (out, tables) = (dir.join("adev.json"), dir.join("tables"));
    let o = rinscope()
        .arg("allan")
        .arg(&log)
        .arg("--json")
        .arg(&out)
        .args(["--no-recording", "--export-format", "csv", "--export"])
        .arg(&tables)
        .output()
        .expect("allan");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("exported 8 tables"), "{}", String::from_utf8_lossy(&o.stdout));
    let j = json(&out);
    for (sensor, key, unit, truth) in
        [("gyro", "n_deg_per_sqrt_h", "deg_per_h", 0.05), ("accel", "n_ug_per_sqrt_hz", "ug", 40.0)]
    {
        for (axis, ch) in ["x", "y", "z"].iter().zip(j[sensor].as_array().expect("channels")) {
            let (value, found) = fitted(ch, key);
            assert!(found && (value / truth - 1.0).abs() < 0.05, "{sensor} {axis} {key}: {value} vs {truth}");
            // The curve table: the JSON's curve, τ increasing, the ADEV inside its bounds.
            let (header, rows) = csv_table(&tables.join(format!("allan__{sensor}_{axis}.csv")));
            let columns = [
                "tau_s".to_owned(),
                format!("adev_{unit}"),
                format!("adev_lower_{unit}"),
                format!("adev_upper_{unit}"),
                format!("fit_adev_{unit}"),
                "edf".into(),
                "second_differences_count".into(),
            ];
            assert_eq!(header, columns, "no configured noise without a table description");
            let taus: Vec<f64> =
                ch["tau_s"].as_array().expect("taus").iter().map(|v| v.as_f64().expect("tau")).collect();
            assert_eq!(rows.len(), taus.len());
            for (r, tau) in rows.iter().zip(&taus) {
                assert_eq!(r[0], *tau, "the same τ as --json (csv round-trips f64 exactly)");
                assert!(r[2] <= r[1] && r[1] <= r[3] && r[5] > 0.0, "bounds and EDF at τ = {tau}: {r:?}");
            }
        }
        // The fit table: one row per axis, the JSON's values and 1σ.
        let (header, rows) = csv_table(&tables.join(format!("allan__{sensor}_fit.csv")));
        assert_eq!(header[0], "axis");
        let (kv, ks, kf) = (
            header.iter().position(|c| c == key).expect("value column"),
            header.iter().position(|c| *c == key.replacen('_', "_sigma_", 1)).expect("sigma column"),
            header.iter().position(|c| c == "n_found").expect("found column"),
        );
        for (row, ch) in rows.iter().zip(j[sensor].as_array().expect("channels")) {
            assert_eq!(
                (row[kv], row[ks], row[kf]),
                (ch["fitted"][key]["value"].as_f64().expect("v"), ch["fitted"][key]["sigma"].as_f64().expect("s"), 1.0),
                "{sensor} {row:?}"
            );
        }
        assert_eq!(rows.iter().map(|r| r[0]).collect::<Vec<_>>(), [0.0, 1.0, 2.0]);
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_rocked_parked_imu_is_warned_about_and_no_false_term_is_claimed() {
    // A navigation-grade IMU (ARW 0.001 °/√h, 10 µg/√Hz, no B, K, R, Q) on a vehicle rocked at 0.7 and
    // 1.3 Hz: the rocking is no IEEE term. Before issue 21 the fit claimed K and R up to 10⁵× above the
    // measured curve; now every reported term stays under the curve's bound and the disturbed axes
    // carry a warning that names the τ range.
    let dir = scratch("rocked");
    let cfg = dir.join("rocked.toml");
    std::fs::write(
        &cfg,
        "[scenario]\nname = \"rocked\"\ntitle = \"t\"\nseed = 7\n[simulation]\nduration_s = 600.0\nstep_hz = 100.0\n[site]\nlatitude_deg = 34.0\n\
         [vehicle]\npitch_deg = 1.2\nroll_deg = -0.7\n[[vehicle.wobble]]\nangle = \"pitch\"\namplitude_deg = 0.05\nfrequency_hz = 0.7\n\
         [[vehicle.wobble]]\nangle = \"roll\"\namplitude_deg = 0.08\nfrequency_hz = 1.3\n\
         [turntable]\n[[turntable.axis]]\nname = \"azimuth\"\naxis = \"z\"\n[scheme]\nkind = \"static\"\n\
         [imu]\n[imu.gyro]\narw_deg_per_sqrt_h = 0.001\n[imu.accel]\nvrw_ug_per_sqrt_hz = 10.0\n",
    )
    .expect("config");
    let out = dir.join("adev.json");
    let o = rinscope()
        .args(["allan", "--config"])
        .arg(&cfg)
        .args(["--json"])
        .arg(&out)
        .arg("--save")
        .arg(dir.join("a.rrd"))
        .output()
        .expect("run");
    assert!(o.status.success(), "{}", stderr(&o));
    let j = json(&out);
    let text = String::from_utf8_lossy(&o.stdout);
    for (sensor, keys) in [
        ("gyro", ["b_deg_per_h", "k_deg_per_h_per_sqrt_h", "r_deg_per_h2", "q_arcsec"]),
        ("accel", ["b_ug", "k_ug_per_sqrt_h", "r_ug_per_h", "q_mps"]),
    ] {
        for ch in j[sensor].as_array().expect("channels") {
            let axis = ch["axis"].as_str().unwrap_or("?");
            for key in keys {
                assert!(!fitted(ch, key).1, "{sensor} {axis}: {key} claimed on a rocked IMU with none configured");
            }
        }
    }
    // The rocked gyros (x: pitch, y: roll) are warned about, in the JSON and in the terminal.
    for k in 0..2 {
        let w = j["gyro"][k]["fit_warnings"].as_array().expect("warnings");
        assert!(!w.is_empty(), "gyro {k}: no warning");
    }
    assert!(text.contains("WARNING gyro x") && text.contains("χ²/dof"), "{text}");
    std::fs::remove_dir_all(&dir).ok();
}
