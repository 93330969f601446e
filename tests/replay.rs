//! Logged data through rinscope: `export-log` then `replay` reproduces the in-loop run, `calibrate
//! --log` the in-loop calibration, every log format gives the same result, `--export` writes
//! readable tables, a strapdown log (no table) records and exports the INS alone, and every kind of
//! bad input is one clear message, exit code 2, nothing written.

mod common;
use common::{csv_table, rinscope, scratch, stderr};
use std::path::{Path, PathBuf};
use std::process::Output;

fn ok(o: &Output) {
    assert!(o.status.success(), "exit {:?}: {}", o.status.code(), stderr(o));
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).expect("json file")).expect("valid json")
}

/// A log set of a scenario preset (default format csv).
fn export(dir: &Path, scenario: &str, format: &str) -> PathBuf {
    let out = dir.join(format!("log-{format}"));
    ok(&rinscope()
        .args(["export-log", "--scenario", scenario, "--format", format, "--out"])
        .arg(&out)
        .output()
        .expect("export-log"));
    out
}

#[test]
fn export_then_replay_reproduces_the_in_loop_run_and_the_calibration() {
    // jiang2017-calibration: an INS with Jiang et al. 2017 Table 1's sensor noise, 12″ encoder noise, both
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
    // Every output instant, through the export tables (t_s, then one column per algorithm; the
    // replay's also t_file_s, the file's clock, after t_s).
    for axis in ["pitch", "roll", "heading"] {
        let name = format!("ins__attitude_error_arcsec__{axis}.csv");
        let ((hx, x), (hy, y)) = (csv_table(&run_tables.join(&name)), csv_table(&replay_tables.join(&name)));
        let column = format!("two_sample_p1_{axis}_error_arcsec");
        let (kx, ky) = (
            hx.iter().position(|c| *c == column).expect("run column"),
            hy.iter().position(|c| *c == column).expect("replay column"),
        );
        assert_eq!(hy[1], "t_file_s", "{hy:?}");
        assert_eq!(x.len(), y.len(), "{axis}: same output instants");
        assert!(x.len() >= 1_900, "{} rows (10 Hz over 200 s)", x.len());
        let peak = x.iter().map(|r| r[kx].abs()).fold(0.0, f64::max);
        for (rx, ry) in x.iter().zip(&y) {
            assert!((rx[0] - ry[0]).abs() < 1e-9, "time {} vs {}", rx[0], ry[0]);
            assert!((rx[kx] - ry[ky]).abs() <= 1e-9 * peak, "{axis} at {} s: {} vs {}", rx[0], rx[kx], ry[ky]);
        }
    }
    // The replay's export has no all-NaN column (the closed form is not replayed) and its layout
    // shows only what its recording holds.
    for name in std::fs::read_dir(&replay_tables).expect("tables").flatten().map(|e| e.path()) {
        let (header, rows) = csv_table(&name);
        for (k, c) in header.iter().enumerate() {
            assert!(rows.iter().any(|r| r[k].is_finite()), "{}: {c} has no finite value", name.display());
        }
    }
    let c = rinscope::record::read::contents(&dir.join("replay.rrd")).expect("recording");
    assert!(c.entities.contains("world/vehicle") && c.entities.contains("ins/body_attitude_deg"), "{:?}", c.entities);
    assert!(c.empty_views().is_empty(), "views of entities the recording lacks: {:?}", c.empty_views());
    // calibrate --log on the exported log: the in-loop calibration's estimates (issue: 1e-6″).
    let (loop_cal, log_cal) = (dir.join("cal-loop.json"), dir.join("cal-log.json"));
    ok(&rinscope().args(["calibrate", "--no-recording", "--json"]).arg(&loop_cal).output().expect("calibrate"));
    ok(&rinscope()
        .args(["calibrate", "--no-recording", "--log"])
        .arg(&log)
        .arg("--json")
        .arg(&log_cal)
        .output()
        .expect("calibrate --log"));
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
    let o = rinscope()
        .arg("replay")
        .arg(&log)
        .arg("--compensation")
        .arg(&log_cal)
        .arg("--save")
        .arg(dir.join("rc.rrd"))
        .output()
        .expect("replay");
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
        // The series rate left to rinscope (the export writes the scenario's 5 Hz): a log's default.
        let table = std::fs::read_to_string(log.join("table.toml")).expect("table.toml");
        let table: Vec<&str> = table.lines().filter(|l| !l.starts_with("series_hz")).collect();
        std::fs::write(log.join("table.toml"), table.join("\n") + "\n").expect("table.toml");
        let out = dir.join(format!("{format}.json"));
        ok(&rinscope()
            .arg("replay")
            .arg(&log)
            .arg("--save")
            .arg(dir.join(format!("{format}.rrd")))
            .arg("--summary-json")
            .arg(&out)
            .output()
            .expect("replay"));
        summaries.push(json(&out)["ins_attitude_error_arcsec"].clone());
        // Each format tells its length before the replay (.npy's shape, Parquet's metadata, the CSV's
        // size): the plots get 3000 buckets over the log, four rows a bucket at most, as a run's do.
        // (50 buckets a second before: 30 000 over this 600-s coning log, its attitude lines varying.)
        let plots = rinscope::record::read::plots(&dir.join(format!("{format}.rrd"))).expect("recording");
        let rows: Vec<(String, usize)> =
            plots.iter().flat_map(|p| &p.series).map(|s| (format!("{} {}", s.entity, s.name), s.t.len())).collect();
        assert!(rows.iter().all(|(_, n)| *n <= 4 * 3000 + 8), "{format}: rows per line {rows:?}");
        assert!(rows.iter().any(|(_, n)| *n > 3000), "{format}: some line varies in every bucket {rows:?}");
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
    let lines: Vec<String> =
        std::fs::read_to_string(base.join(file)).expect("file").lines().map(String::from).collect();
    std::fs::write(out.join(file), edit(lines).join("\n") + "\n").expect("write");
    out
}

#[test]
fn bad_logs_are_refused_with_file_row_and_column() {
    let dir = scratch("bad");
    let base = export(&dir, "jiang2017-calibration", "csv");
    let replace_header = |from: &'static str, to: &'static str| {
        move |mut l: Vec<String>| {
            l[0] = l[0].replace(from, to);
            l
        }
    };
    // A missing column (the message lists the columns there are).
    refused(
        &broken(&base, &dir, "missing", "imu.csv", &replace_header("dv_z_mps", "dv_q_mps")),
        &["imu.csv", "dv_z", "dv_q_mps"],
    );
    // A unit the name does not state / a wrong unit.
    refused(
        &broken(&base, &dir, "unit", "imu.csv", &replace_header("dtheta_x_rad", "dtheta_x_furlong")),
        &["imu.csv", "dtheta_x"],
    );
    // Time going backwards, and a duplicated stamp.
    refused(
        &broken(&base, &dir, "backwards", "imu.csv", &|mut l| {
            l.swap(100, 101);
            l
        }),
        &["imu.csv", "row"],
    );
    refused(
        &broken(&base, &dir, "duplicate", "imu.csv", &|mut l| {
            let x = l[100].clone();
            l.insert(100, x);
            l
        }),
        &["imu.csv", "row"],
    );
    // A gap of 2 s (refused by default).
    refused(
        &broken(&base, &dir, "gap", "imu.csv", &|mut l| {
            l.drain(1000..1400);
            l
        }),
        &["imu.csv", "gap"],
    );
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
    refused(
        &broken(&base, &dir, "truncated", "imu.csv", &|mut l| {
            let n = l.len() - 1;
            l[n] = l[n][..20].to_owned();
            l
        }),
        &["imu.csv", "line"],
    );
    // A file that is not what its extension says.
    let notnpy = broken(&base, &dir, "notnpy", "imu.csv", &|l| l);
    std::fs::rename(notnpy.join("imu.csv"), notnpy.join("imu.npy")).expect("rename");
    let manifest = std::fs::read_to_string(notnpy.join("log.toml"))
        .expect("manifest")
        .replace("file = \"imu.csv\"", "file = \"imu.npy\"\n")
        .replace("layout = \"rinscope\"", "layout = \"npy7\"");
    std::fs::write(notnpy.join("log.toml"), manifest).expect("manifest");
    refused(&notnpy, &["imu.npy"]);
    // Encoder and IMU clocks that do not overlap (the encoder log starts 50 s late).
    refused(
        &broken(&base, &dir, "clocks", "encoders.csv", &|mut l| {
            l.drain(1..10_000);
            l
        }),
        &["encoders.csv", "clocks do not overlap"],
    );
    // Rates declared as increments: the static check sees 1/200 of gravity per sample... as rates.
    let rates = broken(&base, &dir, "rates", "imu.csv", &|l| {
        let mut out = vec![
            "t_s,gyro_x_rad_per_s,gyro_y_rad_per_s,gyro_z_rad_per_s,accel_x_mps2,accel_y_mps2,accel_z_mps2".to_owned(),
        ];
        out.extend(l.into_iter().skip(1));
        out
    });
    let manifest = std::fs::read_to_string(rates.join("log.toml"))
        .expect("manifest")
        .replace(
            "[reference]\nsource = \"the simulation's truth\"\nfile = \"reference.csv\"",
            "[reference]\nattitude_deg = [0.0, 0.0, 0.0]",
        )
        .replace("kind = \"increments\"", "kind = \"rates\"");
    std::fs::write(rates.join("log.toml"), manifest).expect("manifest");
    refused(&rates, &["imu.csv", "increments"]);
    // A typo in the manifest.
    let typo =
        broken(&base, &dir, "typo", "log.toml", &|l| l.into_iter().map(|x| x.replace("rate_hz", "rate_hzz")).collect());
    refused(&typo, &["log.toml", "rate_hzz"]);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn export_tables_read_back_and_say_their_units() {
    let dir = scratch("export");
    let tables = dir.join("tables");
    ok(&rinscope()
        .args(["run", "--scenario", "li2014-coning", "--duration-s", "20", "--save"])
        .arg(dir.join("x.rrd"))
        .arg("--export")
        .arg(&tables)
        .output()
        .expect("run"));
    let names: Vec<String> = std::fs::read_dir(&tables)
        .expect("tables")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().any(|n| n == "ins__attitude_error_arcsec__pitch.parquet"), "{names:?}");
    assert!(names.iter().all(|n| !n.ends_with(".partial")), "{names:?}");
    // Read back with rinscope's own Parquet reader: a t_s column and one arcsec column per algorithm.
    let path = tables.join("ins__attitude_error_arcsec__pitch.parquet");
    let reader = rinscope::io::ColumnReader::open(&path, &[], &rinscope::io::ReadOptions::default()).expect("parquet");
    let cols = reader.all_columns().to_vec();
    assert_eq!(cols[0], "t_s");
    assert_eq!(cols.len(), 6, "{cols:?}");
    assert!(cols[1..].iter().all(|c| c.ends_with("_arcsec")), "{cols:?}");
    // An INS run's layout (five algorithms, the coning log plot, the drift dial) shows only what it holds.
    let c = rinscope::record::read::contents(&dir.join("x.rrd")).expect("recording");
    assert!(c.empty_views().is_empty(), "views of entities the recording lacks: {:?}", c.empty_views());
    std::fs::remove_dir_all(&dir).ok();
}

/// Every column of every table in `dir` has at least two distinct finite values (the issue: no
/// all-NaN or always-equal columns); returns the tables' file names.
fn every_column_varies(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("tables")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    for name in &names {
        let (header, rows) = csv_table(&dir.join(name));
        for (k, column) in header.iter().enumerate() {
            let distinct: std::collections::BTreeSet<u64> =
                rows.iter().map(|r| r[k]).filter(|v| v.is_finite()).map(f64::to_bits).collect();
            assert!(distinct.len() >= 2, "{name}: column {column} has {} distinct finite values", distinct.len());
        }
    }
    names
}

/// A strapdown log set written by the test: 60 s of a vehicle turning (heading 10° → 100° at 3°/s
/// from 5 s) and rolling (3°, 0.2 Hz), Jiang et al. 2017's Table 1 IMU, exported by `export-log` and then
/// stripped of its table (no table.toml, no encoders) with its start position added, as a log of
/// a plain strapdown IMU is written.
fn strapdown_log(dir: &Path) -> PathBuf {
    let scenario = dir.join("moving.toml");
    std::fs::write(
        &scenario,
        "[scenario]\nname = \"moving-imu\"\ntitle = \"t\"\nseed = 7\n[simulation]\nduration_s = 60.0\nstep_hz = 200.0\n[site]\nlatitude_deg = 34.0\n\
         [vehicle]\nheading_deg = 10.0\n[[vehicle.ramp]]\nangle = \"heading\"\nstart_s = 5.0\ntarget_deg = 100.0\nrate_deg_per_s = 3.0\n\
         [[vehicle.wobble]]\nangle = \"roll\"\namplitude_deg = 3.0\nfrequency_hz = 0.2\n\
         [turntable]\n[[turntable.axis]]\nname = \"table\"\naxis = \"z\"\n[scheme]\nkind = \"static\"\n[imu]\npreset = \"jiang2017-table1\"\n",
    )
    .expect("scenario");
    let log = dir.join("strapdown");
    ok(&rinscope()
        .args(["export-log", "--config"])
        .arg(&scenario)
        .arg("--out")
        .arg(&log)
        .output()
        .expect("export-log"));
    std::fs::remove_file(log.join("table.toml")).expect("table.toml");
    std::fs::remove_file(log.join("encoders.csv")).expect("encoders.csv");
    let manifest = std::fs::read_to_string(log.join("log.toml")).expect("manifest");
    let mut kept = Vec::new();
    let mut in_encoders = false;
    for line in manifest.lines() {
        if line.starts_with('[') {
            in_encoders = line == "[encoders]";
        }
        if !in_encoders && !line.starts_with("table = ") {
            kept.push(line.to_owned());
        }
        if line == "[initial]" {
            kept.push("position = [34.0, 0.0, 0.0]".to_owned());
        }
    }
    std::fs::write(log.join("log.toml"), kept.join("\n") + "\n").expect("manifest");
    log
}

#[test]
fn a_strapdown_replay_records_and_exports_the_ins_alone() {
    // Issue "Numbers out" / "Strapdown logs without a table": with no table the recording, the
    // summary and the export hold the INS and nothing of a table; the export is the INS's own
    // solution on the file's clock and, with a reference, its errors, named from the algorithm.
    let dir = scratch("strapdown");
    let log = strapdown_log(&dir);
    let (rrd, tables, summary) = (dir.join("sd.rrd"), dir.join("sd-tables"), dir.join("sd.json"));
    ok(&rinscope()
        .arg("replay")
        .arg(&log)
        .arg("--save")
        .arg(&rrd)
        .arg("--summary-json")
        .arg(&summary)
        .args(["--export-format", "csv", "--export"])
        .arg(&tables)
        .output()
        .expect("replay"));
    let s = json(&summary);
    assert_eq!(s["strapdown"], true);
    assert!(s.get("attitude_error_arcsec").is_none(), "no table rows in the summary: {s}");
    // The recording: the IMU's (body) axes and the reference's, the INS's plots; no gimbal, table,
    // swing, vehicle or trace entity; and its layout shows only what it holds.
    let c = rinscope::record::read::contents(&rrd).expect("recording");
    for table_entity in [
        "world/vehicle",
        "world/ins_trace",
        "gimbal_angle_deg",
        "swing_arcsec",
        "attitude_error_",
        "closed_form",
        "vehicle_attitude_deg",
    ] {
        assert!(!c.entities.iter().any(|e| e.starts_with(table_entity)), "{table_entity}: {:?}", c.entities);
    }
    for wanted in [
        "world/ins_body",
        "world/reference_body",
        "ins/body_attitude_deg",
        "ins/attitude_error_arcsec/heading",
        "ins/velocity_enu_mps",
        "ins/position_from_start_m",
        "ins/latitude_longitude_deg",
    ] {
        assert!(c.entities.contains(wanted), "{wanted}: {:?}", c.entities);
    }
    assert!(c.empty_views().is_empty(), "views of entities the recording lacks: {:?}", c.empty_views());
    // The export: these tables, every column with two distinct finite values or more.
    let names = every_column_varies(&tables);
    let expected = [
        "ins__attitude_error_arcsec__heading.csv",
        "ins__attitude_error_arcsec__pitch.csv",
        "ins__attitude_error_arcsec__roll.csv",
        "ins__body_attitude_deg.csv",
        "ins__gyro_raw_deg_per_s.csv",
        "ins__latitude_longitude_deg.csv",
        "ins__position_from_start_m.csv",
        "ins__velocity_enu_mps.csv",
    ];
    assert_eq!(names, expected);
    let (header, rows) = csv_table(&tables.join("ins__attitude_error_arcsec__heading.csv"));
    assert_eq!(header, ["t_s", "t_file_s", "two_sample_p1_heading_error_arcsec"]);
    // Started from the exact attitude, Jiang et al. 2017's gyros keep the heading within arcseconds in 60 s.
    let peak = rows.iter().map(|r| r[2].abs()).fold(0.0, f64::max);
    assert!(peak < 60.0, "heading error {peak}″");
    // Times: t_file_s is the IMU file's clock, t_s + the summary's t0_file_clock_s.
    let t0 = s["t0_file_clock_s"].as_f64().expect("t0");
    assert!(rows.iter().all(|r| (r[1] - r[0] - t0).abs() < 1e-9), "t_file_s = t_s + {t0}");
    let (header, rows) = csv_table(&tables.join("ins__body_attitude_deg.csv"));
    assert_eq!(header, ["t_s", "t_file_s", "pitch_deg", "roll_deg", "heading_deg"]);
    // The INS's attitude (not a copy of the reference: its error above is not zero) follows the
    // turn from 10° to 100° and the 3° roll.
    let heading: Vec<f64> = rows.iter().map(|r| r[4]).collect();
    assert!(
        heading.iter().copied().fold(f64::INFINITY, f64::min) < 10.5
            && heading.iter().copied().fold(f64::NEG_INFINITY, f64::max) > 99.5,
        "heading {heading:?}"
    );
    assert!(rows.iter().map(|r| r[3].abs()).fold(0.0, f64::max) > 2.9, "roll");
    assert_eq!(
        csv_table(&tables.join("ins__velocity_enu_mps.csv")).0,
        ["t_s", "t_file_s", "east_mps", "north_mps"],
        "held vertical channel: no up column"
    );
    assert_eq!(
        csv_table(&tables.join("ins__latitude_longitude_deg.csv")).0,
        ["t_s", "t_file_s", "latitude_deg", "longitude_deg"]
    );

    // Without a reference: no errors anywhere (they would be zero), no reference axes.
    let manifest = std::fs::read_to_string(log.join("log.toml")).expect("manifest");
    let cut = manifest.replace("[reference]\nsource = \"the simulation's truth\"\nfile = \"reference.csv\"\n", "");
    assert_ne!(cut, manifest, "the reference section was removed");
    std::fs::write(log.join("log.toml"), cut).expect("manifest");
    let (rrd, tables) = (dir.join("noref.rrd"), dir.join("noref-tables"));
    ok(&rinscope()
        .arg("replay")
        .arg(&log)
        .arg("--save")
        .arg(&rrd)
        .args(["--export-format", "csv", "--export"])
        .arg(&tables)
        .output()
        .expect("replay"));
    let c = rinscope::record::read::contents(&rrd).expect("recording");
    assert!(
        !c.entities.iter().any(|e| e.contains("attitude_error")
            || e.starts_with("world/reference_body")
            || e.starts_with("world/vehicle")),
        "{:?}",
        c.entities
    );
    assert!(c.entities.contains("world/ins_body"), "{:?}", c.entities);
    assert!(c.empty_views().is_empty(), "views of entities the recording lacks: {:?}", c.empty_views());
    let names = every_column_varies(&tables);
    assert_eq!(names, expected[3..]);
    std::fs::remove_dir_all(&dir).ok();
}

/// Runs `command` (`replay`, `calibrate`, `allan`) on `log` expecting a refusal: exit 2 and one
/// short message holding every `expected` fragment, nothing saved.
fn refused_by(command: &str, log: &Path, expected: &[&str]) -> String {
    let out = log.join("out.rrd");
    let mut c = rinscope();
    match command {
        "calibrate" => c.args(["calibrate", "--no-recording", "--log"]).arg(log),
        "allan" => c.args(["allan", "--no-recording"]).arg(log),
        _ => c.arg("replay").arg(log).arg("--save").arg(&out),
    };
    let o = c.output().expect(command);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{command}: exit code; stderr: {err}");
    let lines: Vec<&str> =
        err.lines().filter(|l| !l.starts_with("rinscope: saving to") && !l.starts_with("rinscope: reading")).collect();
    // One message (a TOML error quotes its line under it), and a short one.
    assert_eq!(lines.iter().filter(|l| l.starts_with("rinscope: ")).count(), 1, "{command}: one message: {err}");
    let message = lines.join("\n");
    assert!(message.len() < 1000, "{command}: a short message ({} bytes): {err}", message.len());
    for e in expected {
        assert!(err.contains(e), "{command}: stderr should mention `{e}`: {err}");
    }
    assert!(!out.exists() && !log.join("out.rrd.partial").exists(), "nothing written for refused input");
    message
}

/// An edit of a table held as column names and rows.
type TableEdit<'a> = &'a dyn Fn(&mut Vec<String>, &mut Vec<Vec<f64>>);

/// A copy of log set `base` whose file `name` is rewritten by rinscope's writer as `names`/`rows`.
fn rewritten(base: &Path, dir: &Path, case: &str, name: &str, edit: TableEdit<'_>) -> PathBuf {
    let out = broken(base, dir, case, "log.toml", &|l| l);
    // Read from the base: a file this process read is an input its writer refuses to replace.
    let (source, path) = (base.join(name), out.join(name));
    let probe = rinscope::io::ColumnReader::open(&source, &[], &rinscope::io::ReadOptions::default()).expect("probe");
    let n = probe.all_columns().len();
    let cols: Vec<rinscope::io::Col> = (0..n).map(rinscope::io::Col::Index).collect();
    let mut reader =
        rinscope::io::ColumnReader::open(&source, &cols, &rinscope::io::ReadOptions::default()).expect("open");
    let (mut names, mut rows): (Vec<String>, Vec<Vec<f64>>) = ((0..n).map(|i| format!("c{i}")).collect(), Vec::new());
    let mut row = vec![0.0; n];
    while reader.next_row(&mut row).expect("row") {
        rows.push(row.clone());
    }
    drop(reader);
    edit(&mut names, &mut rows);
    std::fs::remove_file(&path).expect("remove");
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    let mut w = rinscope::io::TableWriter::create_keyed(&path, &refs).expect("writer");
    for r in &rows {
        w.write_row(r).expect("row");
    }
    w.finish().expect("finish");
    out
}

#[test]
fn trust_round_2_each_defect_is_refused_where_it_is() {
    // Issue 20, items 3-9: what a hostile user's damaged log sets got through, each refused now by
    // the reader that meets it, with one message naming the file, the row, the column and the value.
    let dir = scratch("trust2");
    let base = export(&dir, "jiang2017-calibration", "csv");
    let set_cell = |line: usize, field: usize, value: &'static str| {
        move |mut l: Vec<String>| {
            let mut f: Vec<String> = l[line].split(',').map(String::from).collect();
            f[field] = value.into();
            l[line] = f.join(",");
            l
        }
    };
    // 6: one finite but absurd value turned the attitude into NaN (exit 0, NaN RMS, nulls).
    let absurd = broken(&base, &dir, "absurd", "imu.csv", &set_cell(500, 2, "1e300"));
    for command in ["replay", "calibrate", "allan"] {
        refused_by(
            command,
            &absurd,
            &["imu.csv", "data row 500 (line 501)", "column dtheta_y_rad", "\"1e300\"", "gyro"],
        );
    }
    refused_by(
        "replay",
        &broken(&base, &dir, "absurd-ref", "reference.csv", &set_cell(9000, 1, "-1e30")),
        &["reference.csv", "line 9001", "pitch_rad", "\"-1e30\""],
    );
    // 3: the last line cut inside its last field, no line end.
    let cut = broken(&base, &dir, "cut", "imu.csv", &|l| l);
    let text = std::fs::read_to_string(cut.join("imu.csv")).expect("imu");
    std::fs::write(cut.join("imu.csv"), &text[..text.len() - 4]).expect("cut");
    refused_by("replay", &cut, &["imu.csv", "the last line has no line end", "truncated"]);
    // 7: a first row that cannot be read is that row's error, not "no IMU samples".
    let first = broken(&base, &dir, "first", "imu.csv", &|mut l| {
        l[1] = "0.0,1e-7".into();
        l
    });
    for command in ["replay", "calibrate", "allan"] {
        let m = refused_by(command, &first, &["imu.csv", "data row 1 (line 2)", "2 fields"]);
        assert!(!m.contains("no IMU samples"), "{m}");
    }
    // 8: damage after the IMU's last stamp in the encoder and reference files.
    let tail = broken(&base, &dir, "tail-enc", "encoders.csv", &|mut l| {
        l.push("1e3,0.1".into());
        l
    });
    refused_by("replay", &tail, &["encoders.csv", "2 fields where the header has 3"]);
    refused_by("calibrate", &tail, &["encoders.csv", "2 fields where the header has 3"]);
    let garbage = broken(&base, &dir, "tail-ref", "log.toml", &|l| l);
    let mut bytes = std::fs::read(garbage.join("reference.csv")).expect("reference");
    bytes.extend([0x00, 0xff, 0x13, b'x', b'\n']);
    std::fs::write(garbage.join("reference.csv"), bytes).expect("garbage");
    refused_by(
        "replay",
        &garbage,
        &["reference.csv", "data row 40003 (line 40004)", "1 fields where the header has 4"],
    );
    // 9: the messages. NaN in an encoder file is not "an IMU log's"; a refused encoder gap has its row.
    let m = refused_by(
        "replay",
        &broken(&base, &dir, "nan-enc", "encoders.csv", &set_cell(300, 1, "NaN")),
        &["encoders.csv", "data row 300 (line 301)", "outer_rad", "NaN"],
    );
    assert!(!m.contains("IMU log"), "{m}");
    let gap = broken(&base, &dir, "enc-gap", "encoders.csv", &|mut l| {
        l.drain(1000..1010);
        l
    });
    refused_by("replay", &gap, &["encoders.csv", "data row 1000 (line 1001)", "a gap of 0.055000 s"]);
    let edit_manifest = |case: &str, from: &str, to: &str| {
        let log = broken(&base, &dir, case, "log.toml", &|l| l);
        let text = std::fs::read_to_string(log.join("log.toml")).expect("manifest");
        assert!(text.contains(from), "{from}");
        std::fs::write(log.join("log.toml"), text.replacen(from, to, 1)).expect("manifest");
        log
    };
    let m = refused_by(
        "replay",
        &edit_manifest("kalibr", "layout = \"rinscope\"", "layout = \"kalibr\""),
        &["imu.csv", "rinscope columns", "use layout = \"rinscope\""],
    );
    assert!(!m.contains("holds rates"), "{m}");
    let m = refused_by(
        "replay",
        &edit_manifest("frame", "frame = \"rfu\"", "frame = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]"),
        &["log.toml", "frame", "2 rows", "3×3 matrix"],
    );
    assert!(!m.contains("untagged"), "{m}");
    refused_by(
        "replay",
        &edit_manifest("topic", "layout = \"rinscope\"", "layout = \"rinscope\"\ntopic = \"/imu\""),
        &["imu.topic", "ros2"],
    );
    refused_by(
        "replay",
        &edit_manifest("latch", "latch_delay_ms = 0.0", "latch_delay_ms = 1e300"),
        &["encoders.latch_delay_ms", "1e300 ms"],
    );
    let nested = broken(&base, &dir, "nested", "log.toml", &|l| l);
    let table = std::fs::read_to_string(nested.join("table.toml")).expect("table");
    std::fs::write(
        nested.join("table.toml"),
        format!("{table}\nx = {}1{}\n", "[".repeat(100_000), "]".repeat(100_000)),
    )
    .expect("table");
    refused_by("replay", &nested, &["table.toml"]);
    // 5: a declared rate the stamps contradict, refused naming both — also by calibrate and allan,
    // and 20 Hz (which made series_hz 25 Hz out of range) no longer blames series_hz.
    for (case, rate) in [("rate20", "20.0"), ("rate210", "210.0")] {
        let log = edit_manifest(case, "rate_hz = 200.0", &format!("rate_hz = {rate}"));
        for command in ["replay", "calibrate", "allan"] {
            let m =
                refused_by(command, &log, &["imu.rate_hz", "the time stamps of", "step by 0.005000 s = 200.0000 Hz"]);
            assert!(!m.contains("series_hz"), "{m}");
        }
    }
    // 4 and 5 on .npy: an array of the wrong width, an encoder or reference file of another width,
    // the npy7 time unit the stamps contradict.
    let npy = export(&dir, "jiang2017-calibration", "npy");
    let wide = rewritten(&npy, &dir, "wide", "imu.npy", &|names, rows| {
        names.push("c7".into());
        rows.iter_mut().for_each(|r| r.push(0.0));
    });
    refused_by("replay", &wide, &["imu.npy", "(N, 8)", "7 columns"]);
    refused_by("allan", &wide, &["imu.npy", "(N, 8)"]);
    let as_encoders = broken(&npy, &dir, "npy-enc", "log.toml", &|l| l);
    std::fs::copy(npy.join("imu.npy"), as_encoders.join("encoders.npy")).expect("copy");
    refused_by("replay", &as_encoders, &["encoders.npy", "7 columns", "holds exactly 3"]);
    let wide_ref = rewritten(&npy, &dir, "npy-ref", "reference.npy", &|names, rows| {
        names.push("c4".into());
        rows.iter_mut().for_each(|r| r.push(1.0));
    });
    refused_by("calibrate", &wide_ref, &["reference.npy", "5 columns", "holds exactly 4"]);
    let ms = broken(&npy, &dir, "npy-ms", "log.toml", &|l| {
        l.into_iter().map(|x| if x == "time = \"s\"" { "time = \"ms\"".to_owned() } else { x }).collect()
    });
    for command in ["replay", "calibrate", "allan"] {
        refused_by(command, &ms, &["imu.rate_hz", "read in ms", "200000"]);
    }
    std::fs::remove_dir_all(&dir).ok();
}
