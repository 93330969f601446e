//! Logs as they come from the field, through `rinscope replay`: a strapdown IMU without a table,
//! a car that is already moving when the log starts (with a reference that starts a second late),
//! a declared rate the stamps contradict, `--from`/`--to`, a parked vehicle aligned on its own data.
//! The moving car's increments are computed here from the WGS84 navigation equations (written
//! out in this file, not taken from rinscope), so the replay is checked against an independent model.

mod common;
use common::{rinscope, scratch, stderr, stdout};
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::Path;
use std::process::Output;

fn ok(o: &Output) {
    assert!(o.status.success(), "exit {:?}: {}{}", o.status.code(), stderr(o), stdout(o));
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).expect("json file")).expect("valid json")
}

// WGS84 (NIMA TR8350.2): semi-major axis, first eccentricity squared, rotation rate; normal gravity
// by Somigliana's formula with the free-air gradient.
const A: f64 = 6_378_137.0;
const E2: f64 = 0.006_694_379_990_14;
const OMEGA: f64 = 7.292_115e-5;

fn gravity(lat: f64, h: f64) -> f64 {
    let s2 = lat.sin().powi(2);
    9.780_325_335_9 * (1.0 + 0.001_931_852_652_41 * s2) / (1.0 - E2 * s2).sqrt() - 3.086e-6 * h
}

fn radii(lat: f64) -> (f64, f64) {
    let d = 1.0 - E2 * lat.sin().powi(2);
    (A * (1.0 - E2) / d.powf(1.5), A / d.sqrt())
}

/// A car driving due North, level, its IMU axes right-forward-up: v_N(t) = v0 + ∫a. Returns the
/// samples (t, Δθ, Δv) at `hz` for `seconds` and the final (latitude rad, v_N m/s). With the body
/// frame equal to ENU at every instant, ω_ib^b = ω_ie^n + ω_en^n and f^b = v̇ + (2ω_ie + ω_en) × v − g,
/// integrated with 20 midpoint sub-steps per sample.
/// Samples (t, Δθ, Δv), the final latitude and speed.
type Drive = (Vec<(f64, [f64; 3], [f64; 3])>, f64, f64);

fn drive_north(lat0: f64, h: f64, v0: f64, accel: impl Fn(f64) -> f64, hz: f64, seconds: f64) -> Drive {
    let dt = 1.0 / hz;
    let sub = 20;
    let ds = dt / sub as f64;
    let (mut lat, mut v, mut t) = (lat0, v0, 0.0);
    let mut out = Vec::new();
    for _ in 0..(seconds * hz).round() as usize {
        let (mut g, mut f) = ([0.0; 3], [0.0; 3]);
        for _ in 0..sub {
            let tm = t + 0.5 * ds;
            let a = accel(tm);
            let vm = v + 0.5 * a * ds;
            let (rm, _) = radii(lat);
            let w_ie = [0.0, OMEGA * lat.cos(), OMEGA * lat.sin()];
            let w_en = [-vm / (rm + h), 0.0, 0.0];
            let w = [w_ie[0] + w_en[0], w_ie[1] + w_en[1], w_ie[2] + w_en[2]];
            // (2ω_ie + ω_en) × (0, v, 0) = (−(2ω_ie,z)·v, 0, (2ω_ie,x + ω_en,x)·v).
            let cor = [-(2.0 * w_ie[2] + w_en[2]) * vm, 0.0, (2.0 * w_ie[0] + w_en[0]) * vm];
            let fs = [cor[0], a + cor[1], cor[2] + gravity(lat, h)];
            for k in 0..3 {
                g[k] += w[k] * ds;
                f[k] += fs[k] * ds;
            }
            lat += vm / (rm + h) * ds;
            v += a * ds;
            t += ds;
        }
        out.push((t, g, f));
    }
    (out, lat, v)
}

fn write_imu_csv(path: &Path, t0: f64, samples: &[(f64, [f64; 3], [f64; 3])]) {
    let mut s = String::from("t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps\n");
    for (t, g, f) in samples {
        writeln!(
            s,
            "{:.6},{:.15e},{:.15e},{:.15e},{:.15e},{:.15e},{:.15e}",
            t0 + t,
            g[0],
            g[1],
            g[2],
            f[0],
            f[1],
            f[2]
        )
        .expect("write");
    }
    std::fs::write(path, s).expect("imu csv");
}

const LAT0_DEG: f64 = 34.0;
const LON0_DEG: f64 = 108.9;
const H0: f64 = 380.0;

#[test]
fn a_car_already_moving_is_navigated_from_the_start_it_is_given_and_refused_without_one() {
    let dir = scratch("moving");
    // Starts at 12 m/s, speeds up and slows down (±0.8 m/s² over 20 s periods): 2 minutes, 100 Hz.
    let accel = |t: f64| 0.8 * (2.0 * PI * t / 20.0).sin();
    let (samples, lat_end, v_end) = drive_north(LAT0_DEG.to_radians(), H0, 12.0, accel, 100.0, 120.0);
    // The file's clock starts at 5000 s (a logger's time of day).
    write_imu_csv(&dir.join("car.csv"), 5000.0, &samples);
    // A reference attitude (level, heading North) from a second after the IMU's first sample.
    let mut r = String::from("t_s,pitch_deg,roll_deg,heading_deg\n");
    for k in 100..=12_000 {
        writeln!(r, "{:.2},0,0,0", 5000.0 + k as f64 * 0.01).expect("write");
    }
    std::fs::write(dir.join("reference.csv"), r).expect("reference");
    std::fs::write(
        dir.join("log.toml"),
        "[log]\nname = \"car\"\n[imu]\nfile = \"car.csv\"\nrate_hz = 100.0\n[reference]\nfile = \"reference.csv\"\n",
    )
    .expect("manifest");
    // Without a start: the IMU alone cannot align a car in motion; the message says so (not "units").
    let o = rinscope()
        .arg("replay")
        .arg(&dir)
        .args(["--position", "34", "108.9", "380", "--save"])
        .arg(dir.join("x.rrd"))
        .output()
        .expect("replay");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("not at rest at the start") && stderr(&o).contains("--velocity-enu-mps"),
        "{}",
        stderr(&o)
    );
    assert!(!stderr(&o).contains("degrees declared as radians"), "{}", stderr(&o));
    assert!(!dir.join("x.rrd").exists());
    // With its attitude, velocity and position: navigated, compared from the reference's start.
    let summary = dir.join("s.json");
    let o = rinscope()
        .arg("replay")
        .arg(&dir)
        .args([
            "--attitude-deg",
            "0",
            "0",
            "0",
            "--velocity-enu-mps",
            "0",
            "12",
            "0",
            "--position",
            "34",
            "108.9",
            "380",
            "--save",
        ])
        .arg(dir.join("car.rrd"))
        .arg("--summary-json")
        .arg(&summary)
        .output()
        .expect("replay");
    ok(&o);
    let s = json(&summary);
    let notes = s["notes"].as_array().expect("notes");
    assert!(
        notes.iter().any(|n| n
            .as_str()
            .is_some_and(|n| n.contains("starts at 5001.000000 s") && n.contains("comparison starts there"))),
        "{notes:?}"
    );
    assert!((s["t0_file_clock_s"].as_f64().expect("t0") - 5000.0).abs() < 0.1, "{}", s["t0_file_clock_s"]);
    let f = &s["final_state"];
    // Ideal sensors: what is left is the navigation's numerical error over 2 minutes, a fraction of
    // a metre and cm/s (the car moved 1.4 km).
    let (rm, _) = radii(lat_end);
    let north_err_m = (f["latitude_deg"].as_f64().expect("lat").to_radians() - lat_end) * (rm + H0);
    let v_err = f["velocity_enu_mps"][1].as_f64().expect("vn") - v_end;
    assert!(north_err_m.abs() < 0.5, "north position error {north_err_m} m");
    assert!(v_err.abs() < 0.01, "north velocity error {v_err} m/s");
    assert!((f["longitude_deg"].as_f64().expect("lon") - LON0_DEG).abs() * 111e3 * 0.83 < 0.5, "east drift");
    let heading_peak =
        s["ins_attitude_error_arcsec"]["two-sample-p1"]["heading"]["peak_arcsec"].as_f64().unwrap_or(f64::NAN);
    assert!(heading_peak < 1.0, "heading error against the level reference {heading_peak}″: {s}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_declared_rate_the_stamps_contradict_is_refused_naming_both() {
    let dir = scratch("rate");
    let (samples, _, _) = drive_north(LAT0_DEG.to_radians(), H0, 0.0, |_| 0.0, 100.0, 20.0);
    write_imu_csv(&dir.join("imu.csv"), 0.0, &samples);
    std::fs::write(
        dir.join("log.toml"),
        "[log]\nname = \"r\"\n[imu]\nfile = \"imu.csv\"\nrate_hz = 20.0\n[initial]\nposition = [34.0, 108.9, 380.0]\n",
    )
    .expect("manifest");
    let o = rinscope().arg("replay").arg(&dir).args(["--save"]).arg(dir.join("x.rrd")).output().expect("replay");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("`imu.rate_hz`: 20 Hz is declared") && stderr(&o).contains("100.0000 Hz"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.join("x.rrd").exists());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_parked_strapdown_imu_is_aligned_on_its_own_data_and_trimmed_on_its_clock() {
    // 150 s at rest (ideal sensors) at 34° N, heading North, level; then --from/--to trim it. The
    // alignment's heading is the exact one (0°) to within its 1σ, and it is reported with its window.
    let dir = scratch("parked");
    let (samples, _, _) = drive_north(LAT0_DEG.to_radians(), H0, 0.0, |_| 0.0, 100.0, 150.0);
    write_imu_csv(&dir.join("imu.csv"), 100.0, &samples);
    std::fs::write(
        dir.join("log.toml"),
        "[log]\nname = \"parked\"\n[imu]\nfile = \"imu.csv\"\n[initial]\nposition = [34.0, 108.9, 380.0]\n",
    )
    .expect("manifest");
    let summary = dir.join("s.json");
    let o = rinscope()
        .arg("replay")
        .arg(&dir)
        .args(["--from", "110", "--to", "240", "--save"])
        .arg(dir.join("p.rrd"))
        .arg("--summary-json")
        .arg(&summary)
        .output()
        .expect("replay");
    ok(&o);
    let s = json(&summary);
    let a = &s["alignment"];
    assert_eq!(s["strapdown"], true);
    let heading = a["imu_heading_deg"].as_f64().expect("heading");
    let sigma = a["sigma_deg"][2].as_f64().expect("σ");
    let off = (heading + 180.0).rem_euclid(360.0) - 180.0;
    assert!(off.abs() < 3.0 * sigma.max(1e-4), "heading {heading}° ± {sigma}°");
    assert!((a["window_from_s"].as_f64().expect("from") - 110.0).abs() < 0.05, "{a}");
    assert!(a["warnings"].as_array().expect("warnings").is_empty(), "{a}");
    // Ran from 110 s to 240 s on the file's clock: the window (130 s at rest) and nothing after 240 s.
    assert!(s["duration_s"].as_f64().expect("duration") < 0.05, "{s}");
    // No table in a strapdown summary.
    assert!(s.get("attitude_error_arcsec").is_none(), "{s}");
    assert!(stdout(&o).contains("alignment") && !stdout(&o).contains("nominal"), "{}", stdout(&o));
    std::fs::remove_dir_all(&dir).ok();
}

#[path = "io/psins_writer.rs"]
#[allow(dead_code)]
mod psins_writer;

/// A PSINS SIMU file (as `imufile.m` writes it) of `samples` (t, Δθ, Δv) with header `avp0` =
/// [pitch, roll, yaw (deg; PSINS's yaw is counter-clockwise), VE, VN, VU, lat, lon (deg), h, t0].
fn write_psins(path: &Path, samples: &[(f64, [f64; 3], [f64; 3])], avp0: [f64; 10], ts: f64) {
    let imu: Vec<[f64; 7]> =
        samples.iter().map(|(t, g, f)| [g[0], g[1], g[2], f[0], f[1], f[2], avp0[9] + t]).collect();
    // A ring-laser gyro's 0.01″ pulses and 1 µg·s accelerometer pulses (PSINS's own defaults are 0.1″, 125 µg·s).
    let input = psins_writer::SimuInput { imu, avp0, ts, scales: [0.01, 0.01, 0.01, 1.0, 1.0, 1.0] };
    std::fs::write(path, psins_writer::imufile_text(&input)).expect("psins file");
}

/// An IMU fixed on the Earth at `lat` with body attitude (pitch, roll, heading clockwise), exact:
/// ω^b = C_n^b ω_ie^n, f^b = C_n^b (0, 0, g), C_b^n = Rz(−heading) Rx(pitch) Ry(roll) (ENU, RFU).
fn parked(
    lat: f64,
    h: f64,
    pitch: f64,
    roll: f64,
    heading: f64,
    hz: f64,
    seconds: f64,
) -> Vec<(f64, [f64; 3], [f64; 3])> {
    use nalgebra::{Rotation3, Vector3};
    let c_bn = Rotation3::from_axis_angle(&Vector3::z_axis(), -heading)
        * Rotation3::from_axis_angle(&Vector3::x_axis(), pitch)
        * Rotation3::from_axis_angle(&Vector3::y_axis(), roll);
    let w = c_bn.inverse() * Vector3::new(0.0, OMEGA * lat.cos(), OMEGA * lat.sin());
    let f = c_bn.inverse() * Vector3::new(0.0, 0.0, gravity(lat, h));
    let dt = 1.0 / hz;
    // The body turns with the Earth in inertial space (ω^b constant), so the increments are ω·dt, f·dt
    // up to second-order terms of (Ω dt)² ~ 5e-13.
    (1..=(seconds * hz).round() as usize).map(|k| (k as f64 * dt, (w * dt).into(), (f * dt).into())).collect()
}

#[test]
fn a_psins_imu_file_replays_with_nothing_else_and_is_aligned_on_its_data() {
    // `rinscope replay --imu run.imu` alone: the header gives the rate, the site and a (deliberately
    // 2° wrong) heading; the vehicle is parked, so the INS aligns on the data and finds the true one.
    let dir = scratch("psins");
    let (lat, heading) = (34.246_048_f64, 90.6_f64);
    let samples = parked(
        lat.to_radians(),
        380.0,
        0.3_f64.to_radians(),
        -0.2_f64.to_radians(),
        heading.to_radians(),
        100.0,
        600.0,
    );
    // PSINS yaw = −heading; the header says −92.6 (heading 92.6°).
    write_psins(&dir.join("run.imu"), &samples, [0.3, -0.2, -92.6, 0.0, 0.0, 0.0, lat, 108.909_664, 380.0, 0.0], 0.01);
    let summary = dir.join("s.json");
    let o = rinscope()
        .arg("replay")
        .arg("--imu")
        .arg(dir.join("run.imu"))
        .arg("--save")
        .arg(dir.join("r.rrd"))
        .arg("--summary-json")
        .arg(&summary)
        .output()
        .expect("replay");
    ok(&o);
    let s = json(&summary);
    let a = &s["alignment"];
    assert!((a["latitude_site_deg"].as_f64().expect("lat") - lat).abs() < 1e-6, "the site is the header's: {a}");
    let (h, sigma) = (a["imu_heading_deg"].as_f64().expect("heading"), a["sigma_deg"][2].as_f64().expect("σ"));
    assert!((h - heading).abs() < 3.0 * sigma + 0.01, "heading {h}° ± {sigma}° vs the true {heading}°");
    assert!((h - heading).abs() < 0.5, "heading {h}° vs the true {heading}° (the header's 92.6° was not taken)");
    assert!(
        stdout(&o).contains("PSINS header") && stdout(&o).contains("92.6"),
        "the header's heading is compared: {}",
        stdout(&o)
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_psins_imu_file_that_starts_moving_starts_from_its_header() {
    let dir = scratch("psins-moving");
    let accel = |t: f64| 0.8 * (2.0 * PI * t / 20.0).sin();
    let (samples, lat_end, v_end) = drive_north(LAT0_DEG.to_radians(), H0, 12.0, accel, 100.0, 60.0);
    write_psins(&dir.join("car.imu"), &samples, [0.0, 0.0, 0.0, 0.0, 12.0, 0.0, LAT0_DEG, LON0_DEG, H0, 0.0], 0.01);
    let summary = dir.join("s.json");
    let o = rinscope()
        .arg("replay")
        .arg("--imu")
        .arg(dir.join("car.imu"))
        .arg("--save")
        .arg(dir.join("c.rrd"))
        .arg("--summary-json")
        .arg(&summary)
        .output()
        .expect("replay");
    ok(&o);
    let s = json(&summary);
    assert!(
        s["notes"].to_string().contains("moves at the start") && s["notes"].to_string().contains("PSINS header"),
        "{}",
        s["notes"]
    );
    let f = &s["final_state"];
    let (rm, _) = radii(lat_end);
    let north_err_m = (f["latitude_deg"].as_f64().expect("lat").to_radians() - lat_end) * (rm + H0);
    assert!(north_err_m.abs() < 1.0, "north {north_err_m} m");
    assert!((f["velocity_enu_mps"][1].as_f64().expect("vn") - v_end).abs() < 0.02);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_headerless_file_is_described_column_by_column_instead_of_rewritten() {
    // A MEMS logger's text: time in ms, a counter, accelerometers in g then gyros in °/s, axes
    // forward-right-down, no header, no rate declared. [imu.columns] says which column is what.
    let dir = scratch("columns");
    let (lat, heading) = (LAT0_DEG, 30.0_f64);
    let samples = parked(lat.to_radians(), H0, 0.0, 0.0, heading.to_radians(), 50.0, 120.0);
    let mut text = String::new();
    for (k, (t, g, f)) in samples.iter().enumerate() {
        // RFU → FRD: (y, x, −z); increments over 0.02 s → rates.
        let (w, a) = ([g[1], g[0], -g[2]].map(|x| x / 0.02), [f[1], f[0], -f[2]].map(|x| x / 0.02));
        let deg = |x: f64| x.to_degrees();
        let gee = |x: f64| x / 9.806_65;
        writeln!(
            text,
            "{:.3} {k} {:.12e} {:.12e} {:.12e} {:.12e} {:.12e} {:.12e}",
            1000.0 * (1.0 + t),
            gee(a[0]),
            gee(a[1]),
            gee(a[2]),
            deg(w[0]),
            deg(w[1]),
            deg(w[2])
        )
        .expect("write");
    }
    std::fs::write(dir.join("mems.txt"), text).expect("file");
    let columns = "[imu.columns]\ntime = { column = 0, unit = \"ms\" }\n\
        accel_x = { column = 2, unit = \"g\" }\naccel_y = { column = 3, unit = \"g\" }\naccel_z = { column = 4, unit = \"g\" }\n\
        gyro_x = { column = 5, unit = \"deg_per_s\" }\ngyro_y = { column = 6, unit = \"deg_per_s\" }\ngyro_z = { column = 7, unit = \"deg_per_s\" }\n";
    let manifest = |frame: &str| {
        format!(
            "[log]\nname = \"mems\"\n[imu]\nfile = \"mems.txt\"\n{frame}[initial]\nposition = [{LAT0_DEG}, {LON0_DEG}, {H0}]\n{columns}"
        )
    };
    // No frame: the message asks for it by key.
    std::fs::write(dir.join("log.toml"), manifest("")).expect("manifest");
    let o = rinscope().arg("replay").arg(&dir).arg("--save").arg(dir.join("x.rrd")).output().expect("replay");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("imu.frame"), "{}", stderr(&o));
    std::fs::write(dir.join("log.toml"), manifest("frame = \"frd\"\n")).expect("manifest");
    let summary = dir.join("s.json");
    let o = rinscope()
        .arg("replay")
        .arg(&dir)
        .arg("--save")
        .arg(dir.join("m.rrd"))
        .arg("--summary-json")
        .arg(&summary)
        .output()
        .expect("replay");
    ok(&o);
    let a = &json(&summary)["alignment"];
    let (h, sigma) = (a["imu_heading_deg"].as_f64().expect("heading"), a["sigma_deg"][2].as_f64().expect("σ"));
    assert!(
        (h - heading).abs() < (3.0 * sigma).max(0.01),
        "heading {h}° ± {sigma}° vs {heading}°: the columns, units and frame were read as described"
    );
    // A unit of the wrong quantity is named with its key.
    std::fs::write(
        dir.join("log.toml"),
        manifest("frame = \"frd\"\n").replace("column = 5, unit = \"deg_per_s\"", "column = 5, unit = \"mps2\""),
    )
    .expect("manifest");
    let o = rinscope().arg("replay").arg(&dir).arg("--save").arg(dir.join("y.rrd")).output().expect("replay");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("imu.columns.gyro_x") && stderr(&o).contains("mps2"), "{}", stderr(&o));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn data_from_another_latitude_than_the_site_s_are_warned_about() {
    // A parked IMU at 42° N declared at 34° N: gravity turns with the Earth at Ω cos 42°, not cos 34°;
    // the alignment says so (and the heading it finds is then not to be trusted).
    let dir = scratch("latitude");
    let samples = parked(42.0_f64.to_radians(), H0, 0.0, 0.0, 1.0, 100.0, 300.0);
    write_imu_csv(&dir.join("imu.csv"), 0.0, &samples);
    let summary = dir.join("s.json");
    let o = rinscope()
        .arg("replay")
        .arg("--imu")
        .arg(dir.join("imu.csv"))
        .args(["--position", "34", "108.9", "380", "--save"])
        .arg(dir.join("l.rrd"))
        .arg("--summary-json")
        .arg(&summary)
        .output()
        .expect("replay");
    ok(&o);
    let a = &json(&summary)["alignment"];
    let (lat, sigma) =
        (a["latitude_implied_deg"][0].as_f64().expect("lat"), a["latitude_implied_deg"][1].as_f64().expect("σ"));
    assert!((lat - 42.0).abs() < 3.0 * sigma + 0.1, "implied {lat}° ± {sigma}°");
    assert!(a["warnings"].to_string().contains("imply a latitude"), "{a}");
    assert!(stdout(&o).contains("WARNING"), "{}", stdout(&o));
    std::fs::remove_dir_all(&dir).ok();
}

/// The offsets of the records of `opcode` in an MCAP file: after the 8-byte magic, each record is
/// an opcode byte, a u64 little-endian length and that many bytes (the MCAP specification).
fn mcap_records(bytes: &[u8], opcode: u8) -> Vec<usize> {
    let (mut at, mut found) = (8, Vec::new());
    while at + 9 <= bytes.len() {
        if bytes[at] == opcode {
            found.push(at);
        }
        let len = u64::from_le_bytes(bytes[at + 1..at + 9].try_into().expect("8 bytes")) as usize;
        at += 9 + len;
    }
    found
}

#[test]
fn an_mcap_chunk_that_does_not_read_as_one_is_damage_not_a_shorter_log() {
    use rinscope::io::{Col, ColumnReader, ReadOptions};
    let dir = scratch("mcap-chunk");
    // 20 s of a still IMU at 200 Hz, in chunks of ~16 kB (about 10 of them), with the summary's
    // statistics counting the messages, written by the `mcap` crate.
    let rows: Vec<Vec<f64>> = (0..4000).map(|k| vec![1e9 + k as f64 * 5e6, 1e-5, 0.0, 0.0, 0.0, 0.0, 9.8]).collect();
    let whole = dir.join("whole.mcap");
    common::write_imu_mcap(&whole, &rows, Some(16_384));
    let bytes = std::fs::read(&whole).expect("mcap");
    let chunks = mcap_records(&bytes, 0x06);
    assert!(chunks.len() >= 5, "{} chunks", chunks.len());
    let read_all = |path: &Path| -> Result<usize, String> {
        let cols: Vec<Col> = (0..7).map(Col::Index).collect();
        let mut r = ColumnReader::open(path, &cols, &ReadOptions::default()).map_err(|e| e.to_string())?;
        let (mut row, mut n) = (vec![0.0; 7], 0);
        while r.next_row(&mut row).map_err(|e| e.to_string())? {
            n += 1;
        }
        Ok(n)
    };
    assert_eq!(read_all(&whole), Ok(4000));
    // A chunk's opcode changed: a reader skips a record it does not know (the rule for newer
    // opcodes), and the log read on as if it started later, ended earlier or had a hole.
    for (which, at) in [("first", chunks[0]), ("middle", chunks[chunks.len() / 2]), ("last", chunks[chunks.len() - 1])]
    {
        let mut damaged = bytes.clone();
        damaged[at] ^= 0x5a;
        let path = dir.join(format!("{which}.mcap"));
        std::fs::write(&path, &damaged).expect("write");
        let e = read_all(&path).expect_err(which);
        assert!(
            e.contains("summary counts 4000 messages on /imu") && e.contains(&format!("{which}.mcap")),
            "{which}: {e}"
        );
        // And through `replay`, a replay of what is left would have said nothing.
        let o = rinscope()
            .args(["replay", "--imu"])
            .arg(&path)
            .args(["--position", "40", "116", "50", "--save"])
            .arg(dir.join("x.rrd"))
            .output()
            .expect("replay");
        assert_eq!(o.status.code(), Some(2), "{which}: {}", stderr(&o));
        assert!(!dir.join("x.rrd").exists(), "{which}: no recording of a damaged log");
    }
}
