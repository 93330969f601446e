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
    // The alignment writes the one compensation document too: the summary's
    // estimated_imu_compensation holds its biases (each with its 1σ, the gains named not
    // compensated), and a replay given it aligns on the compensated IMU and finds nothing left.
    let doc = &s["estimated_imu_compensation"];
    assert_eq!(doc["accel_bias_ug"], al["accel_bias_ug"], "{doc}");
    assert_eq!(doc["sigma"]["accel_bias_ug"], al["accel_bias_sigma_ug"], "{doc}");
    assert!(doc["not_compensated"].to_string().contains("gains"), "{doc}");
    let out = rinscope()
        .arg("replay")
        .arg("--imu")
        .arg(&imu)
        .args([
            "--position",
            "34",
            "0",
            "0",
            "--save",
            "r2.rrd",
            "--summary-json",
            "s2.json",
            "--compensation",
            "s.json",
        ])
        .current_dir(&dir)
        .output()
        .expect("runs");
    assert!(out.status.success(), "{}", stderr(&out));
    let s2: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("s2.json")).expect("summary")).expect("json");
    assert!(s2["notes"].to_string().contains("the IMU is compensated with s.json's estimates"), "{}", s2["notes"]);
    // What the second alignment finds is within 3σ of zero (the data are the same: the residual of
    // a bias it already removed), and the document it writes carries the first one's on top.
    let (again, sigma) = (&s2["alignment"]["accel_bias_ug"], &s2["alignment"]["accel_bias_sigma_ug"]);
    for i in 0..3 {
        let (r, sg) = (again[i].as_f64().expect("bias"), sigma[i].as_f64().expect("1σ"));
        assert!(r.abs() < 3.0 * sg, "residual accelerometer bias {i}: {r} µg (1σ {sg})");
        let (first, total) = (
            doc["accel_bias_ug"][i].as_f64().expect("first"),
            s2["estimated_imu_compensation"]["accel_bias_ug"][i].as_f64().expect("total"),
        );
        assert!((total - first - r).abs() < 1e-6 * first.abs().max(1.0), "{total} vs {first} + {r}");
    }
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
    // 4. The same documents in the loop: `run --compensation` on the scenario the log came from
    //    (the computer removes the IMU part from every sample and starts aligned in the frame it
    //    then measures in; the table part replaces the scenario's [compensation]).
    let run = |document: Option<&str>| {
        let mut cmd = rinscope();
        cmd.args(["run", "--config", "rot.toml", "--save", "run.rrd", "--summary-json", "run.json"]).current_dir(&dir);
        if let Some(d) = document {
            cmd.args(["--compensation", d]);
        }
        let out = cmd.output().expect("runs");
        assert!(out.status.success(), "{}", stderr(&out));
        let s: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("run.json")).expect("json")).expect("json");
        s["navigation"]["peak_radial_m"].as_f64().expect("navigated")
    };
    let (run_none, run_estimated, run_truth) = (run(None), run(Some("sc.json")), run(Some("truth.json")));
    eprintln!("run, peak drift: none {run_none:.0} m, estimated {run_estimated:.0} m, truth {run_truth:.0} m");
    // In the loop there is no alignment to absorb anything: what is left is the sensors' noise and
    // the estimates' own error, a tenth of the uncompensated drift or less (measured 1606 → 125 m,
    // the truth 120 m).
    assert!(run_estimated < 0.2 * run_none, "run: estimated {run_estimated:.0} m vs none {run_none:.0} m");
    assert!(run_estimated < 1.3 * run_truth + 50.0, "run: estimated {run_estimated:.0} m vs truth {run_truth:.0} m");
    // 5. The same documents in a live session (`live --compensation`): the table part written into
    //    the session's config, the IMU part removed from the INS's samples; 20 simulated minutes
    //    at 1000× real time, the INS's attitude errors exported.
    let live = |name: &str, document: Option<&str>| {
        std::fs::write(dir.join(format!("{name}.toml")), &preset).expect("write");
        let mut cmd = rinscope();
        cmd.args(["live", "--config", &format!("{name}.toml"), "--no-viewer", "--no-panel", "--speed", "1000"])
            .args(["--duration-s", "1200", "--save", &format!("{name}.rrd"), "--export", name])
            .current_dir(&dir);
        if let Some(d) = document {
            cmd.args(["--compensation", d]);
        }
        let out = cmd.output().expect("runs");
        assert!(out.status.success(), "{}", stderr(&out));
        let rms: Vec<f64> = ["heading", "pitch", "roll"]
            .iter()
            .map(|a| {
                let v = parquet_column(&dir.join(name).join(format!("ins__attitude_error_arcsec__{a}.parquet")), 1);
                // (Rows before the INS's first attitude update are empty: NaN.)
                let v: Vec<f64> = v.into_iter().filter(|x| x.is_finite()).collect();
                assert!(v.len() >= 100, "{name}: {} rows of {a} (1 per 10 s at 1000×)", v.len());
                (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
            })
            .collect();
        (rms, stderr(&out))
    };
    let (live_none, live_estimated, live_truth) =
        (live("live-none", None), live("live-sc", Some("sc.json")), live("live-truth", Some("truth.json")));
    eprintln!(
        "live, INS attitude error RMS (heading, pitch, roll ″): none {:.2?}, estimated {:.2?}, truth {:.2?}",
        live_none.0, live_estimated.0, live_truth.0
    );
    assert!(live_estimated.1.contains("the IMU is compensated with sc.json's estimates"), "{}", live_estimated.1);
    // The table part is now the config's: every key of sc.json's estimated_compensation, its value.
    let cfg: toml::Value =
        toml::from_str(&std::fs::read_to_string(dir.join("live-sc.toml")).expect("cfg")).expect("toml");
    for (axis, fields) in sc["estimated_compensation"]["axis"].as_object().expect("axes") {
        for (field, value) in fields.as_object().expect("fields") {
            let written = cfg["compensation"]["axis"][axis][field].as_float().expect("written");
            assert!((written - value.as_f64().expect("number")).abs() < 1e-5, "{axis}.{field}: {written} vs {value}");
        }
    }
    // The preset's IMU errors are tens of times the estimates' 1σ (the accuracy table): compensated,
    // every axis's error falls at least five-fold, and stays within what the truth leaves plus 1″
    // (the estimates' own error over 20 minutes: 1σ 0.0009 °/h of gyro bias is 0.3″ of heading).
    let total = |r: &[f64]| r.iter().map(|x| x * x).sum::<f64>().sqrt();
    assert!(total(&live_estimated.0) < 0.2 * total(&live_none.0), "{live_estimated:?} vs {live_none:?}");
    assert!(total(&live_estimated.0) < total(&live_truth.0) + 1.0, "{live_estimated:?} vs {live_truth:?}");
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

/// Column `index` of a Parquet table (`--export`), read with the parquet crate's own arrow reader.
fn parquet_column(path: &std::path::Path, index: usize) -> Vec<f64> {
    use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
    let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let reader = ParquetRecordBatchReaderBuilder::try_new(file).expect("parquet").build().expect("reader");
    let mut out = Vec::new();
    for batch in reader {
        let batch = batch.expect("batch");
        let col = batch.column(index).as_any().downcast_ref::<arrow_array::Float64Array>().expect("f64 column");
        out.extend(col.values().iter().copied());
    }
    out
}

/// PSINS `imufile.m`'s writer (the format `io::formats::psins_imu` documents): `%` comments, the
/// three header rows, then per sample the integer counts `diff(fix(cumsum(x / scale)))`.
fn psins_imu(rows: &[[f64; 7]], lat_deg: f64, lon_deg: f64, h_m: f64, ts_s: f64) -> String {
    let (gf_arcsec, af_ug_s, g) = (1e-4, 1e-3, 9.80665);
    let rad_per_count = gf_arcsec * std::f64::consts::PI / 180.0 / 3600.0;
    let mps_per_count = af_ug_s * 1e-6 * g;
    let t0 = rows[0][0] - ts_s;
    let mut out = format!(
        "% PSINS-format SIMU log file. (DO NOT MODIFY!)\n% written by rinscope's tests/issue32.rs\n\n\
         0.000000 0.000000 0.000000 0.000000 0.000000 0.000000\n\
         {lat_deg:.8} {lon_deg:.8} {h_m:.3} {t0:.8} {:.8} {g:.6}\n\
         {gf_arcsec:.6} {gf_arcsec:.6} {gf_arcsec:.6} {af_ug_s:.3} {af_ug_s:.3} {af_ug_s:.3}\n\n",
        ts_s * 1e3
    );
    let (mut sum, mut last) = ([0.0f64; 6], [0i64; 6]);
    for r in rows {
        let mut counts = [0i64; 6];
        for i in 0..6 {
            sum[i] += r[1 + i] / if i < 3 { rad_per_count } else { mps_per_count };
            let whole = sum[i].trunc() as i64;
            counts[i] = whole - last[i];
            last[i] = whole;
        }
        out.push_str(&counts.map(|c| c.to_string()).join(" "));
        out.push('\n');
    }
    out
}

#[test]
fn a_psins_imu_with_an_encoder_file_is_self_calibrated_then_replayed() {
    // A RINS's sequence written in another tool's format: the IMU as PSINS's `imufile.m` writes a
    // SIMU `.imu` (integer counts, its own header), the encoders as a CSV in degrees; only the table
    // description comes from rinscope (the instrument the user describes). Short: the preset's own
    // two-move [scheme], 960 s.
    let dir = scratch("issue32-psins");
    let preset =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenarios/selfcal-nav-grade.toml"))
            .expect("preset");
    std::fs::write(dir.join("short.toml"), preset.replace("duration_s = 5400.0", "duration_s = 960.0")).expect("write");
    let ok = |args: &[&str]| {
        let out = rinscope().args(args).current_dir(&dir).output().expect("runs");
        assert!(out.status.success(), "{args:?}: {}", stderr(&out));
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    ok(&["export-log", "--config", "short.toml", "--format", "csv", "--out", "sim"]);
    let table = |name: &str| -> Vec<Vec<f64>> {
        let text = std::fs::read_to_string(dir.join("sim").join(name)).expect("csv");
        text.lines().skip(1).map(|l| l.split(',').map(|x| x.parse().expect("number")).collect()).collect()
    };
    // The samples after t = 0 (the export's first two are the INS's pre-roll).
    let imu: Vec<[f64; 7]> =
        table("imu.csv").into_iter().filter(|r| r[0] > 1e-3).map(|r| std::array::from_fn(|i| r[i])).collect();
    let log = dir.join("psins");
    std::fs::create_dir_all(&log).expect("dir");
    std::fs::write(log.join("run.imu"), psins_imu(&imu, 39.9042, 116.4074, 44.0, 0.005)).expect("imu");
    let deg = 180.0 / std::f64::consts::PI;
    let encoders: String = std::iter::once("t_s,outer_deg,inner_deg".to_owned())
        .chain(table("encoders.csv").into_iter().map(|r| format!("{},{},{}", r[0], r[1] * deg, r[2] * deg)))
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(log.join("enc.csv"), encoders + "\n").expect("encoders");
    std::fs::copy(dir.join("sim/table.toml"), log.join("table.toml")).expect("table");
    // The body's true attitude, for the replay's comparison (the vehicle stands level).
    std::fs::copy(dir.join("sim/reference.csv"), log.join("reference.csv")).expect("reference");
    std::fs::write(
        log.join("log.toml"),
        "[log]\nname = \"psins-rins\"\ntable = \"table.toml\"\n[imu]\nfile = \"run.imu\"\nlayout = \"psins-imu\"\nrate_hz = 200.0\n[encoders]\nfile = \"enc.csv\"\n[reference]\nfile = \"reference.csv\"\n",
    )
    .expect("manifest");
    ok(&["selfcal", "--log", "psins", "--no-recording", "--json", "psins.json"]);
    ok(&[
        "selfcal",
        "--config",
        "short.toml",
        "--sequence",
        "scenario",
        "--no-recording",
        "--navigate-hours",
        "0",
        "--json",
        "loop.json",
    ]);
    let read = |p: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.join(p)).expect("json")).expect("json")
    };
    let (psins, in_loop) = (read("psins.json"), read("loop.json"));
    assert_eq!(psins["parameters"], in_loop["parameters"]);
    let names: Vec<&str> =
        in_loop["parameters"].as_array().expect("names").iter().map(|n| n.as_str().expect("name")).collect();
    let ratio = in_loop["observability"]["ratio"].as_array().expect("ratio");
    let mut compared = 0;
    for (k, name) in names.iter().enumerate() {
        // What the sequence sees well: the PSINS file gives the loop's estimate (its counts are
        // within a count, 1e-4″ and 1e-3 µg·s, of the increments).
        if ratio[k].as_f64().expect("ratio") < 0.1 {
            let (a, b, s) = (
                psins["estimate"][k].as_f64().expect("estimated"),
                in_loop["estimate"][k].as_f64().expect("estimated"),
                in_loop["sigma"][k].as_f64().expect("sigma"),
            );
            assert!((a - b).abs() < 0.1 * s, "{name}: PSINS file {a} vs in loop {b} (1σ {s})");
            compared += 1;
        }
    }
    assert!(compared >= 10 && names.iter().any(|n| n.starts_with("inner.")), "{compared} compared: {names:?}");
    assert!(psins["estimated_compensation"]["axis"]["inner"].is_object(), "{psins}");
    // Then the same log replayed with what it calibrated, against the nominal table.
    std::fs::write(dir.join("nothing.json"), r#"{"estimated_compensation": {"enabled": false}}"#).expect("write");
    let replay = |doc: &str| {
        ok(&["replay", "psins", "--compensation", doc, "--save", "r.rrd", "--summary-json", "s.json"]);
        let s = read("s.json");
        s["attitude_error_arcsec"]["compensated"]["heading"]["rms_arcsec"].as_f64().expect("heading")
    };
    let (nominal, calibrated) = (replay("nothing.json"), replay("psins.json"));
    eprintln!("PSINS log replayed: heading RMS {nominal:.1}″ nominal table, {calibrated:.1}″ with its selfcal");
    assert!(calibrated < 0.1 * nominal, "{calibrated} vs {nominal}");
}
