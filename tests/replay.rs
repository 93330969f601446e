//! Logged data through rinscope: `export-log` then `replay` reproduces the in-loop run, `calibrate
//! --log` the in-loop calibration, every log format gives the same result, `--export` writes
//! readable tables, and every kind of bad input is one clear message, exit code 2, nothing written.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn rinscope() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rinscope"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rinscope-replay-{}-{name}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn ok(o: &Output) {
    assert!(o.status.success(), "exit {:?}: {}", o.status.code(), stderr(o));
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).expect("json file")).expect("valid json")
}

/// A log set of a scenario preset (default format csv).
fn export(dir: &Path, scenario: &str, format: &str) -> PathBuf {
    let out = dir.join(format!("log-{format}"));
    ok(&rinscope().args(["export-log", "--scenario", scenario, "--format", format, "--out"]).arg(&out).output().expect("export-log"));
    out
}

#[test]
fn export_then_replay_reproduces_the_in_loop_run_and_the_calibration() {
    // jiang2017-calibration: an INS with seed 000 Table 1's sensor noise, 12″ encoder noise, both
    // gimbals turning. The replay runs the same navigation computer on the logged samples, so the
    // INS errors must equal the in-loop run's (issue: within 1e-9 of their size), here compared
    // sample by sample through --export, and in the summaries.
    let dir = scratch("roundtrip");
    let log = export(&dir, "jiang2017-calibration", "csv");
    let (run_json, run_tables) = (dir.join("run.json"), dir.join("run-tables"));
    ok(&rinscope()
        .args(["run", "--scenario", "jiang2017-calibration", "--save"])
        .arg(dir.join("run.rrd"))
        .arg("--summary-json")
        .arg(&run_json)
        .args(["--export-format", "csv", "--export"])
        .arg(&run_tables)
        .output()
        .expect("run"));
    let (replay_json, replay_tables) = (dir.join("replay.json"), dir.join("replay-tables"));
    ok(&rinscope()
        .arg("replay")
        .arg(&log)
        .arg("--save")
        .arg(dir.join("replay.rrd"))
        .arg("--summary-json")
        .arg(&replay_json)
        .args(["--export-format", "csv", "--export"])
        .arg(&replay_tables)
        .output()
        .expect("replay"));
    let (a, b) = (json(&run_json), json(&replay_json));
    let (a, b) = (&a["ins_attitude_error_arcsec"], &b["ins_attitude_error_arcsec"]);
    let mut compared = 0;
    for (alg, axes) in a.as_object().expect("algorithms") {
        for (axis, v) in axes.as_object().expect("axes") {
            for stat in ["rms_arcsec", "peak_arcsec"] {
                let (x, y) = (v[stat].as_f64().expect("number"), b[alg][axis][stat].as_f64().expect("replayed"));
                assert!(x > 1.0, "the errors are arcseconds of noise: {x}");
                assert!((x - y).abs() <= 1e-9 * x.abs(), "{alg} {axis} {stat}: in loop {x}, replayed {y}");
                compared += 1;
            }
        }
    }
    assert_eq!(compared, 6);
    // Every output instant, through the export tables (t_s, then one column per algorithm).
    for axis in ["pitch", "roll", "heading"] {
        let name = format!("ins__attitude_error_arcsec__{axis}.csv");
        let (x, y) = (std::fs::read_to_string(run_tables.join(&name)).expect("run table"), std::fs::read_to_string(replay_tables.join(&name)).expect("replay table"));
        let rows = |t: &str| t.lines().skip(1).map(|l| l.split(',').map(|v| v.parse::<f64>().expect("number")).collect::<Vec<f64>>()).collect::<Vec<_>>();
        let (x, y) = (rows(&x), rows(&y));
        assert_eq!(x.len(), y.len(), "{axis}: same output instants");
        assert!(x.len() >= 1_900, "{} rows (10 Hz over 200 s)", x.len());
        let peak = x.iter().map(|r| r[1].abs()).fold(0.0, f64::max);
        for (rx, ry) in x.iter().zip(&y) {
            assert!((rx[0] - ry[0]).abs() < 1e-9, "time {} vs {}", rx[0], ry[0]);
            assert!((rx[1] - ry[1]).abs() <= 1e-9 * peak, "{axis} at {} s: {} vs {}", rx[0], rx[1], ry[1]);
        }
    }
    // calibrate --log on the exported log: the in-loop calibration's estimates (issue: 1e-6″).
    let (loop_cal, log_cal) = (dir.join("cal-loop.json"), dir.join("cal-log.json"));
    ok(&rinscope().args(["calibrate", "--no-recording", "--json"]).arg(&loop_cal).output().expect("calibrate"));
    ok(&rinscope().args(["calibrate", "--no-recording", "--log"]).arg(&log).arg("--json").arg(&log_cal).output().expect("calibrate --log"));
    let (a, b) = (json(&loop_cal), json(&log_cal));
    for section in ["state", "angles"] {
        for (ra, rb) in a[section].as_array().expect("rows").iter().zip(b[section].as_array().expect("rows")) {
            for est in ["kf", "nls"] {
                let (x, y) = (ra[est]["value"].as_f64().expect("value"), rb[est]["value"].as_f64().expect("value"));
                // Angles in arcsec, phases in deg (1e-6″ of phase is 2.8e-10°).
                let tol = if ra["unit"] == "deg" { 1e-6 / 3600.0 } else { 1e-6 };
                assert!((x - y).abs() <= tol, "{} {est}: in loop {x}, from the log {y}", ra["key"]);
            }
        }
    }
    // And replay --compensation takes the calibration's estimates.
    let o = rinscope().arg("replay").arg(&log).arg("--compensation").arg(&log_cal).arg("--save").arg(dir.join("rc.rrd")).output().expect("replay");
    ok(&o);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn every_log_format_replays_to_the_same_result() {
    // The same simulated log as CSV, NumPy and Parquet (the readers' own tests add MCAP, PSINS,
    // KF-GINS and Kalibr layouts against the same samples: tests/io/formats.rs).
    let dir = scratch("formats");
    let mut summaries = Vec::new();
    for format in ["csv", "npy", "parquet"] {
        let log = export(&dir, "li2014-coning", format);
        let out = dir.join(format!("{format}.json"));
        ok(&rinscope().arg("replay").arg(&log).arg("--save").arg(dir.join(format!("{format}.rrd"))).arg("--summary-json").arg(&out).output().expect("replay"));
        summaries.push(json(&out)["ins_attitude_error_arcsec"].clone());
    }
    assert!(summaries[0].as_object().is_some_and(|m| m.len() == 5), "five algorithms compared: {}", summaries[0]);
    assert_eq!(summaries[0], summaries[1], "csv vs npy");
    assert_eq!(summaries[0], summaries[2], "csv vs parquet");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn an_imu_file_replays_with_flags_instead_of_a_manifest() {
    // `replay --imu FILE --imu-frame frd ...`: the exported log's RFU increments rewritten in FRD
    // (x_frd = y_rfu, y_frd = x_rfu, z_frd = −z_rfu), a static table, the body attitude given.
    let dir = scratch("flags");
    let scenario = dir.join("static.toml");
    std::fs::write(
        &scenario,
        "[scenario]\nname = \"static-imu\"\ntitle = \"t\"\nseed = 3\n[simulation]\nduration_s = 60.0\nstep_hz = 200.0\n[site]\nlatitude_deg = 34.0\n\
         [vehicle]\nheading_deg = 30.0\n[turntable]\n[[turntable.axis]]\nname = \"table\"\naxis = \"z\"\n[scheme]\nkind = \"static\"\n\
         [imu]\npreset = \"jiang2017-table1\"\n",
    )
    .expect("scenario");
    let log = dir.join("log");
    ok(&rinscope().args(["export-log", "--config"]).arg(&scenario).arg("--out").arg(&log).output().expect("export"));
    let rfu = std::fs::read_to_string(log.join("imu.csv")).expect("imu");
    let mut frd = String::from("t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps\n");
    for line in rfu.lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().expect("number")).collect();
        frd.push_str(&format!("{},{},{},{},{},{},{}\n", v[0], v[2], v[1], -v[3], v[5], v[4], -v[6]));
    }
    std::fs::write(dir.join("flight.csv"), frd).expect("frd");
    let out = dir.join("flags.json");
    let o = rinscope()
        .arg("replay")
        .arg("--imu")
        .arg(dir.join("flight.csv"))
        .args(["--imu-kind", "increments", "--imu-frame", "frd", "--rate-hz", "200", "--table"])
        .arg(log.join("table.toml"))
        .args(["--attitude-deg", "0", "0", "30", "--save"])
        .arg(dir.join("flags.rrd"))
        .arg("--summary-json")
        .arg(&out)
        .output()
        .expect("replay --imu");
    ok(&o);
    let s = json(&out);
    // At rest on a static table with a good IMU the attitude error is arcseconds, not degrees: the
    // frame was converted (a wrong one gives tens of degrees at once).
    for axis in ["pitch", "roll", "heading"] {
        let peak = s["attitude_error_arcsec"]["compensated"][axis]["peak_arcsec"].as_f64().expect("number");
        assert!(peak < 60.0, "{axis}: {peak}″");
    }
    // The same file declared RFU is refused by the plausibility check or gives degrees of error.
    std::fs::remove_dir_all(&dir).ok();
}

/// Replays `log` expecting refusal: exit 2, every `expected` fragment in the message, no recording.
fn refused(log: &Path, expected: &[&str]) {
    let out = log.join("out.rrd");
    let o = rinscope().arg("replay").arg(log).arg("--save").arg(&out).output().expect("replay");
    assert_eq!(o.status.code(), Some(2), "exit code; stderr: {}", stderr(&o));
    for e in expected {
        assert!(stderr(&o).contains(e), "stderr should mention `{e}`: {}", stderr(&o));
    }
    assert!(!out.exists() && !log.join("out.rrd.partial").exists(), "nothing written for refused input");
}

/// A copy of the exported log set `base` with `file` rewritten by `edit` (its lines).
fn broken(base: &Path, dir: &Path, name: &str, file: &str, edit: &dyn Fn(Vec<String>) -> Vec<String>) -> PathBuf {
    let out = dir.join(name);
    std::fs::create_dir_all(&out).expect("dir");
    for e in std::fs::read_dir(base).expect("log").flatten() {
        std::fs::copy(e.path(), out.join(e.file_name())).expect("copy");
    }
    let lines: Vec<String> = std::fs::read_to_string(base.join(file)).expect("file").lines().map(String::from).collect();
    std::fs::write(out.join(file), edit(lines).join("\n") + "\n").expect("write");
    out
}

#[test]
fn bad_logs_are_refused_with_file_row_and_column() {
    let dir = scratch("bad");
    let base = export(&dir, "jiang2017-calibration", "csv");
    let replace_header = |from: &'static str, to: &'static str| move |mut l: Vec<String>| {
        l[0] = l[0].replace(from, to);
        l
    };
    // A missing column (the message lists the columns there are).
    refused(&broken(&base, &dir, "missing", "imu.csv", &replace_header("dv_z_mps", "dv_q_mps")), &["imu.csv", "dv_z", "dv_q_mps"]);
    // A unit the name does not state / a wrong unit.
    refused(&broken(&base, &dir, "unit", "imu.csv", &replace_header("dtheta_x_rad", "dtheta_x_furlong")), &["imu.csv", "dtheta_x"]);
    // Time going backwards, and a duplicated stamp.
    refused(&broken(&base, &dir, "backwards", "imu.csv", &|mut l| { l.swap(100, 101); l }), &["imu.csv", "row"]);
    refused(&broken(&base, &dir, "duplicate", "imu.csv", &|mut l| { let x = l[100].clone(); l.insert(100, x); l }), &["imu.csv", "row"]);
    // A gap of 2 s (refused by default).
    refused(&broken(&base, &dir, "gap", "imu.csv", &|mut l| { l.drain(1000..1400); l }), &["imu.csv", "gap"]);
    // A NaN row.
    refused(
        &broken(&base, &dir, "nan", "imu.csv", &|mut l| {
            let mut f: Vec<String> = l[500].split(',').map(String::from).collect();
            f[3] = "NaN".into();
            l[500] = f.join(",");
            l
        }),
        &["imu.csv", "dtheta_z_rad", "NaN"],
    );
    // A truncated last line.
    refused(&broken(&base, &dir, "truncated", "imu.csv", &|mut l| { let n = l.len() - 1; l[n] = l[n][..20].to_owned(); l }), &["imu.csv", "line"]);
    // A file that is not what its extension says.
    let notnpy = broken(&base, &dir, "notnpy", "imu.csv", &|l| l);
    std::fs::rename(notnpy.join("imu.csv"), notnpy.join("imu.npy")).expect("rename");
    let manifest = std::fs::read_to_string(notnpy.join("log.toml")).expect("manifest").replace("file = \"imu.csv\"", "file = \"imu.npy\"\n").replace("layout = \"rinscope\"", "layout = \"npy7\"");
    std::fs::write(notnpy.join("log.toml"), manifest).expect("manifest");
    refused(&notnpy, &["imu.npy"]);
    // Encoder and IMU clocks that do not overlap (the encoder log starts 50 s late).
    refused(&broken(&base, &dir, "clocks", "encoders.csv", &|mut l| { l.drain(1..10_000); l }), &["encoders.csv", "clocks do not overlap"]);
    // Rates declared as increments: the static check sees 1/200 of gravity per sample... as rates.
    let rates = broken(&base, &dir, "rates", "imu.csv", &|l| {
        let mut out = vec!["t_s,gyro_x_rad_per_s,gyro_y_rad_per_s,gyro_z_rad_per_s,accel_x_mps2,accel_y_mps2,accel_z_mps2".to_owned()];
        out.extend(l.into_iter().skip(1));
        out
    });
    let manifest = std::fs::read_to_string(rates.join("log.toml")).expect("manifest").replace("[reference]\nsource = \"the simulation's truth\"\nfile = \"reference.csv\"", "[reference]\nattitude_deg = [0.0, 0.0, 0.0]").replace("kind = \"increments\"", "kind = \"rates\"");
    std::fs::write(rates.join("log.toml"), manifest).expect("manifest");
    refused(&rates, &["imu.csv", "increments"]);
    // A typo in the manifest.
    let typo = broken(&base, &dir, "typo", "log.toml", &|l| l.into_iter().map(|x| x.replace("rate_hz", "rate_hzz")).collect());
    refused(&typo, &["log.toml", "rate_hzz"]);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn export_tables_read_back_and_say_their_units() {
    let dir = scratch("export");
    let tables = dir.join("tables");
    ok(&rinscope().args(["run", "--scenario", "li2014-coning", "--duration-s", "20", "--save"]).arg(dir.join("x.rrd")).arg("--export").arg(&tables).output().expect("run"));
    let names: Vec<String> = std::fs::read_dir(&tables).expect("tables").flatten().map(|e| e.file_name().to_string_lossy().into_owned()).collect();
    assert!(names.iter().any(|n| n == "ins__attitude_error_arcsec__pitch.parquet"), "{names:?}");
    assert!(names.iter().all(|n| !n.ends_with(".partial")), "{names:?}");
    // Read back with rinscope's own Parquet reader: a t_s column and one arcsec column per algorithm.
    let path = tables.join("ins__attitude_error_arcsec__pitch.parquet");
    let reader = rinscope::io::ColumnReader::open(&path, &[], &rinscope::io::ReadOptions::default()).expect("parquet");
    let cols = reader.all_columns().to_vec();
    assert_eq!(cols[0], "t_s");
    assert_eq!(cols.len(), 6, "{cols:?}");
    assert!(cols[1..].iter().all(|c| c.ends_with("_arcsec")), "{cols:?}");
    std::fs::remove_dir_all(&dir).ok();
}
