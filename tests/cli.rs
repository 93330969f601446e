//! End-to-end checks of the `rinscope` binary: bad input is refused with exit code 2 and a message
//! naming key, value and unit, leaving no file behind; a good run writes a complete recording and
//! a summary whose numbers are consistent with the physics.

mod common;
use common::{rinscope, scratch, stderr};
use std::path::{Path, PathBuf};

const PRESET: &str = include_str!("../assets/scenarios/jiang2017-dual-axis.toml");

/// The preset with one line replaced (the test's typo).
fn with_edit(dir: &Path, from: &str, to: &str) -> PathBuf {
    assert!(PRESET.contains(from), "the preset has `{from}`");
    let path = dir.join("edited.toml");
    std::fs::write(&path, PRESET.replacen(from, to, 1)).expect("write config");
    path
}

fn refused(dir: &Path, cfg: &Path, expected: &[&str]) {
    let out_file = dir.join("out.rrd");
    let o = rinscope().args(["run", "--config"]).arg(cfg).arg("--save").arg(&out_file).output().expect("run");
    assert_eq!(o.status.code(), Some(2), "exit code; stderr: {}", stderr(&o));
    for e in expected {
        assert!(stderr(&o).contains(e), "stderr should mention `{e}`: {}", stderr(&o));
    }
    assert!(!out_file.exists(), "no recording for a refused config");
    assert!(!dir.join("out.rrd.partial").exists(), "no partial file either");
}

#[test]
fn a_typo_in_a_key_is_refused_with_its_line() {
    let dir = scratch("typo");
    let cfg = with_edit(&dir, "swing_half_angle_arcsec = 300.0", "swing_half_angl_arcsec = 300.0");
    refused(
        &dir,
        &cfg,
        &["unknown key `swing_half_angl_arcsec`; did you mean `swing_half_angle_arcsec`?", "valid keys here"],
    );
}

#[test]
fn a_wrong_type_is_refused() {
    let dir = scratch("type");
    let cfg = with_edit(&dir, "duration_s = 360.0", "duration_s = \"long\"");
    refused(&dir, &cfg, &["duration_s", "invalid type"]);
}

#[test]
fn nan_and_out_of_range_angles_are_refused_with_key_value_and_unit() {
    let dir = scratch("nan");
    let cfg = with_edit(&dir, "swing_half_angle_arcsec = 300.0", "swing_half_angle_arcsec = nan");
    refused(&dir, &cfg, &["swing_half_angle_arcsec", "NaN", "arcsec", "not a finite number"]);
    // 20 deg typed into an arcsec key: over the 10 deg limit.
    let cfg = with_edit(&dir, "swing_half_angle_arcsec = 300.0", "swing_half_angle_arcsec = 72000");
    refused(&dir, &cfg, &["swing_half_angle_arcsec", "72000 arcsec", "out of range", "36000"]);
    let cfg = with_edit(&dir, "latitude_deg = 39.9042", "latitude_deg = 123");
    refused(&dir, &cfg, &["site.latitude_deg", "123 deg"]);
}

#[test]
fn recording_choices_are_refused_by_name_with_the_allowed_values() {
    let dir = scratch("recording-choice");
    let cfg = with_edit(&dir, "# open_at = \"start\"", "open_at = \"middle\"");
    refused(&dir, &cfg, &["recording.open_at", "middle", "\"start\" or \"end\""]);
    let cfg = with_edit(&dir, "# error_unit = \"arcmin\"", "error_unit = \"mrad\"");
    refused(&dir, &cfg, &["recording.error_unit", "mrad", "arcsec"]);
}

#[test]
fn an_unknown_axis_in_the_scheme_is_refused() {
    let dir = scratch("axis");
    let cfg = with_edit(&dir, "axis = \"outer\"          # axis name (required)", "axis = \"middle\"");
    refused(&dir, &cfg, &["scheme.rate[0].axis", "middle", "outer"]);
}

#[test]
fn a_missing_file_is_refused() {
    let o = rinscope().args(["run", "--config", "/nonexistent/scenario.toml"]).output().expect("run");
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("/nonexistent/scenario.toml"));
}

#[test]
fn spawn_without_a_viewer_says_how_to_get_one() {
    let dir = scratch("spawn");
    let o = rinscope().args(["run", "--spawn"]).env("PATH", &dir).current_dir(&dir).output().expect("run");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("pip install rerun-sdk==0.36.3"), "{}", stderr(&o));
    assert!(!dir.join("recordings").exists(), "nothing written");
}

#[test]
fn connect_to_nothing_is_refused() {
    // A port nobody listens on: bind one, read its number, close it.
    let port = std::net::TcpListener::bind("127.0.0.1:0").expect("bind").local_addr().expect("addr").port();
    let url = format!("rerun+http://127.0.0.1:{port}/proxy");
    let o = rinscope().args(["run", "--connect", &url]).output().expect("run");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("no viewer is listening"), "{}", stderr(&o));
}

#[test]
fn a_run_writes_a_complete_recording_and_a_consistent_summary() {
    let dir = scratch("run");
    let rrd = dir.join("short.rrd");
    let json = dir.join("summary.json");
    let o = rinscope()
        .args(["run", "--scenario", "jiang2017-dual-axis", "--duration-s", "40", "--save"])
        .arg(&rrd)
        .arg("--summary-json")
        .arg(&json)
        .output()
        .expect("run");
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(&rrd).expect("recording exists");
    // RRD files start with the magic "RRF2".
    assert_eq!(&bytes[..4], b"RRF2", "an RRD file");
    assert!(!dir.join("short.rrd.partial").exists());
    // Its layout shows only entities it holds.
    let c = rinscope::record::read::contents(&rrd).expect("readable");
    assert!(c.entities.contains("world/vehicle") && c.view_origins.contains("world"), "{c:?}");
    assert!(c.empty_views().is_empty(), "views of entities the recording lacks: {:?}", c.empty_views());

    let summary: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).expect("summary")).expect("json");
    assert_eq!(summary["steps"], 40 * 200 + 1);
    let e = &summary["attitude_error_arcsec"];
    // Jiang et al. 2017 Table 2 errors are arcminutes: the uncompensated heading error peaks at several arcmin,
    // bounded by the sum of the error angles (10' + 5' + 20" = 920").
    let heading = e["uncompensated"]["heading"]["peak_arcsec"].as_f64().expect("number");
    assert!(heading > 300.0 && heading < 920.0, "heading peak {heading}");
    // Compensating with the true parameters leaves nothing (a wiring check: the compensated chain
    // is the truth's exact inverse by construction, so this is not evidence of the physics).
    for axis in ["pitch", "roll", "heading"] {
        assert!(e["compensated"][axis]["peak_arcsec"].as_f64().expect("number") < 1e-3);
    }
    assert!(summary["wall_time_s"].as_f64().expect("number") > 0.0);
}

#[test]
fn scenarios_lists_every_preset() {
    let o = rinscope().arg("scenarios").output().expect("run");
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    for name in [
        "jiang2017-dual-axis (default)",
        "rotary-table-2016-installation",
        "rotary-table-2016-wobble",
        "rotary-table-2016-angular",
    ] {
        assert!(text.contains(name), "{text}");
    }
}

#[test]
fn a_headless_live_session_runs_for_its_duration_and_saves() {
    let dir = scratch("live");
    let cfg = dir.join("live.toml");
    std::fs::write(&cfg, PRESET).expect("config");
    let rrd = dir.join("live.rrd");
    let o = rinscope()
        .args(["live", "--config"])
        .arg(&cfg)
        .args(["--no-viewer", "--no-panel", "--speed", "100", "--duration-s", "30", "--save"])
        .arg(&rrd)
        .output()
        .expect("run");
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("30.0 s simulated"), "{stdout}");
    assert_eq!(&std::fs::read(&rrd).expect("saved")[..4], b"RRF2");
    // Nothing to keep and no viewer: refused.
    let o = rinscope().args(["live", "--config"]).arg(&cfg).arg("--no-viewer").output().expect("run");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

#[test]
fn tpr_refuses_a_scenario_without_fixes_and_leaves_no_file() {
    // The dual-axis preset has no [imu], [navigation] or position fixes: tpr must say what is
    // missing, exit 2, and write nothing.
    let dir = scratch("tpr-refused");
    let cfg = dir.join("plain.toml");
    std::fs::write(&cfg, PRESET).expect("write config");
    let out_file = dir.join("tpr.rrd");
    let o = rinscope().args(["tpr", "--config"]).arg(&cfg).arg("--save").arg(&out_file).output().expect("run");
    assert_eq!(o.status.code(), Some(2), "stderr: {}", stderr(&o));
    assert!(stderr(&o).contains("position_fix") || stderr(&o).contains("navigation"), "{}", stderr(&o));
    assert!(!out_file.exists() && !dir.join("tpr.rrd.partial").exists(), "no file for a refused run");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn events_refuse_a_damaged_recording_by_what_is_wrong_and_read_one_cut_short_with_a_note() {
    let dir = scratch("damaged-rrd");
    let rrd = dir.join("whole.rrd");
    let o = rinscope()
        .args(["run", "--scenario", "jiang2017-dual-axis", "--duration-s", "20", "--save"])
        .arg(&rrd)
        .output()
        .expect("run");
    assert!(o.status.success(), "{}", stderr(&o));
    let events = |path: &Path| rinscope().arg("events").arg(path).output().expect("events");
    let whole = events(&rrd);
    assert!(whole.status.success(), "{}", stderr(&whole));
    let listed = String::from_utf8_lossy(&whole.stdout).to_string();
    assert!(listed.contains("run started") && stderr(&whole).is_empty(), "{listed}\n{}", stderr(&whole));
    let bytes = std::fs::read(&rrd).expect("recording");
    let n = bytes.len();
    // Rerun's frames (re_log_encoding 0.36): a 12-byte stream header ("RRF2", version, options),
    // 16-byte message headers, and at the end a 32-byte stream footer: the footer payload's start
    // and length (u64 each), its CRC (u32), "RRF2", "FOOT" and the number of entries (u32).
    let variant = |name: &str, data: &[u8]| {
        let p = dir.join(name);
        std::fs::write(&p, data).expect("write variant");
        p
    };
    let flipped = |at: usize| {
        let mut b = bytes.clone();
        b[at] ^= 0x5a;
        b
    };
    for (name, data, expected) in [
        ("count.rrd", flipped(n - 1), "entries, not 1"),
        ("crc.rrd", flipped(n - 16), "checksum"),
        ("message.rrd", flipped(12), "stop being readable at byte"),
        ("empty.rrd", Vec::new(), "0 bytes"),
        ("header.rrd", flipped(0), "FourCC"),
        // Two recordings one after the other (`cat a.rrd b.rrd`): named as such, also when the
        // first one's footer is damaged (Rerun's decoder would reach it and abort).
        ("twice.rrd", [bytes.as_slice(), &bytes].concat(), "more than one recording"),
        ("twice-damaged.rrd", [flipped(n - 1).as_slice(), &bytes].concat(), "the last starts at byte"),
    ] {
        let path = variant(name, &data);
        let o = events(&path);
        // Exit 2, not an abort (the footer's entry count made Rerun's decoder allocate ~36 GB).
        assert_eq!(o.status.code(), Some(2), "{name}: {}", stderr(&o));
        assert!(stderr(&o).contains(expected) && stderr(&o).contains(name), "{name}: {}", stderr(&o));
        assert!(o.stdout.is_empty(), "{name}: nothing listed");
    }
    // Cut short (a copy that stopped): its events, and a note that it is not a finished file.
    let cut = events(&variant("cut.rrd", &bytes[..n - 5]));
    assert!(cut.status.success(), "{}", stderr(&cut));
    assert_eq!(String::from_utf8_lossy(&cut.stdout), listed, "the messages before the footer are all there");
    assert!(stderr(&cut).contains("cut short"), "{}", stderr(&cut));
    // The same bytes while another process holds the file's lock (a run writing its `.partial`):
    // not "cut short" but still being written.
    let partial = variant("live.rrd.partial", &bytes[..n - 5]);
    let writer = std::fs::OpenOptions::new().append(true).open(&partial).expect("open the partial");
    writer.lock().expect("lock it as a writing run does");
    let live = events(&partial);
    assert!(live.status.success(), "{}", stderr(&live));
    assert_eq!(String::from_utf8_lossy(&live.stdout), listed);
    assert!(stderr(&live).contains("still being written") && !stderr(&live).contains("cut short"), "{}", stderr(&live));
    writer.unlock().expect("unlock");
    assert!(stderr(&events(&partial)).contains("cut short"), "its writer gone, the same file was cut short");
    // A live session's first seconds: its writer has put nothing out yet.
    let empty = variant("new.rrd.partial", &[]);
    let writer = std::fs::OpenOptions::new().append(true).open(&empty).expect("open the partial");
    writer.lock().expect("lock it as a writing run does");
    let early = events(&empty);
    assert!(early.status.success() && early.stdout.is_empty(), "{}", stderr(&early));
    assert!(
        stderr(&early).contains("still being written") && stderr(&early).contains("0 bytes so far"),
        "{}",
        stderr(&early)
    );
}
