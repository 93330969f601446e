//! `rinscope sweep` on the real binary: every point is exactly the `run` of the scenario file with
//! its keys set (checked against separate `run` processes on files this test edits itself, not by
//! rinscope's editor), seeds are the scenario's and the following ones, the points run on the
//! threads asked for, and a key or value the scenario cannot take is refused before anything runs.

mod common;
use common::{rinscope, scratch, stderr};

const DUAL_AXIS: &str = include_str!("../assets/scenarios/jiang2017-dual-axis.toml");
const NAV_GRADE: &str = include_str!("../assets/scenarios/selfcal-nav-grade.toml");

fn json(path: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())))
        .expect("json")
}

/// `run --config` of `text` for `duration` s, its summary.
fn run(dir: &std::path::Path, name: &str, text: &str, duration: &str) -> serde_json::Value {
    std::fs::write(dir.join(format!("{name}.toml")), text).expect("write");
    let out = rinscope()
        .args(["run", "--config", &format!("{name}.toml"), "--duration-s", duration, "--save"])
        .arg(format!("{name}.rrd"))
        .args(["--summary-json", &format!("{name}.json")])
        .current_dir(dir)
        .output()
        .expect("runs");
    assert!(out.status.success(), "{}", stderr(&out));
    json(&dir.join(format!("{name}.json")))
}

#[test]
fn every_point_is_the_run_of_its_file() {
    let dir = scratch("points");
    let out = rinscope()
        .args(["sweep", "--vary", "turntable.axis[1].swing_half_angle_arcsec=0,600", "--duration-s", "120"])
        .args(["--threads", "2", "--json", "sw.json"])
        .current_dir(&dir)
        .output()
        .expect("runs");
    assert!(out.status.success(), "{}", stderr(&out));
    let sw = json(&dir.join("sw.json"));
    assert_eq!(sw["threads"], 2);
    let points = sw["points"].as_array().expect("points");
    assert_eq!(points.len(), 2);
    // The inner axis is the second [[turntable.axis]]; its swing is written "= 300.0" in the preset.
    let inner = DUAL_AXIS.find("name = \"inner\"").expect("inner axis");
    for (point, value) in points.iter().zip(["0.0", "600.0"]) {
        let (head, tail) = DUAL_AXIS.split_at(inner);
        let edited = format!(
            "{head}{}",
            tail.replacen("swing_half_angle_arcsec = 300.0", &format!("swing_half_angle_arcsec = {value}"), 1)
        );
        assert_ne!(edited, DUAL_AXIS);
        let alone = run(&dir, &format!("inner-{value}"), &edited, "120");
        assert_eq!(point["values"][0][1].as_f64(), value.parse::<f64>().ok());
        // Every statistic the same number, bit for bit (the same file, the same seed, another process).
        assert_eq!(point["summary"]["attitude_error_arcsec"], alone["attitude_error_arcsec"], "{value}");
        assert_eq!(point["summary"]["steps"], alone["steps"]);
    }
    // The swing shows: the inner cone of 600″ adds to the outer's 600″ in the raw heading (measured
    // 420″ → 456″ RMS over these 120 s).
    let raw = |p: &serde_json::Value| {
        p["summary"]["attitude_error_arcsec"]["uncompensated"]["heading"]["rms_arcsec"].as_f64().expect("rms")
    };
    assert!(raw(&points[1]) > raw(&points[0]) + 20.0, "{} vs {}", raw(&points[1]), raw(&points[0]));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn seeds_are_the_scenarios_and_the_following_ones() {
    let dir = scratch("seeds");
    let out = rinscope()
        .args(["sweep", "--scenario", "selfcal-nav-grade", "--seeds", "2", "--duration-s", "300", "--json", "sw.json"])
        .current_dir(&dir)
        .output()
        .expect("runs");
    assert!(out.status.success(), "{}", stderr(&out));
    let sw = json(&dir.join("sw.json"));
    let points = sw["points"].as_array().expect("points");
    assert_eq!(points.iter().map(|p| p["seed"].as_u64().expect("seed")).collect::<Vec<_>>(), [2024, 2025]);
    let alone = run(&dir, "seed-2025", &NAV_GRADE.replacen("seed = 2024", "seed = 2025", 1), "300");
    assert_eq!(points[1]["summary"]["ins_attitude_error_arcsec"], alone["ins_attitude_error_arcsec"]);
    // Another seed, another IMU noise: not the same numbers.
    assert_ne!(points[0]["summary"]["ins_attitude_error_arcsec"], points[1]["summary"]["ins_attitude_error_arcsec"]);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_key_or_value_the_scenario_cannot_take_is_refused_before_anything_runs() {
    let dir = scratch("refused");
    for (vary, says) in [
        ("turntable.axis[1].swing_half_angle_arcsex=1,2", "swing_half_angle_arcsex"),
        ("turntable.axis[1].swing_half_angle_arcsec=300,1e9", "1000000000"),
        ("turntable.axis[1].swing_half_angle_arcsec=300,nan", "not a finite number"),
    ] {
        let out =
            rinscope().args(["sweep", "--vary", vary, "--json", "sw.json"]).current_dir(&dir).output().expect("runs");
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{vary}: {err}");
        assert!(err.contains(says), "{vary}: {err}");
        assert!(!dir.join("sw.json").exists(), "{vary}: a document of a refused sweep");
    }
    let out = rinscope().arg("sweep").current_dir(&dir).output().expect("runs");
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("nothing to sweep"), "{}", stderr(&out));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn shards_in_separate_processes_merge_into_the_unsharded_sweep() {
    let dir = scratch("shards");
    let sweep = |extra: &[&str]| {
        let out = rinscope()
            .args(["sweep", "--vary", "turntable.axis[1].swing_half_angle_arcsec=0,300,600", "--seeds", "2"])
            .args(["--duration-s", "30"])
            .args(extra)
            .current_dir(&dir)
            .output()
            .expect("runs");
        assert!(out.status.success(), "{}", stderr(&out));
    };
    sweep(&["--json", "whole.json"]);
    for k in 0..3 {
        sweep(&["--shard", &format!("{k}/3"), "--json", &format!("part-{k}.json")]);
    }
    let merge = |files: &[&str]| {
        rinscope()
            .args(["sweep", "--merge"])
            .args(files)
            .args(["--json", "all.json"])
            .current_dir(&dir)
            .output()
            .expect("runs")
    };
    let out = merge(&["part-2.json", "part-0.json", "part-1.json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (whole, all) = (json(&dir.join("whole.json")), json(&dir.join("all.json")));
    let runs = |r: &serde_json::Value| -> Vec<serde_json::Value> {
        r["points"]
            .as_array()
            .expect("points")
            .iter()
            .map(|p| serde_json::json!([p["index"], p["values"], p["seed"], p["summary"]["attitude_error_arcsec"]]))
            .collect()
    };
    assert_eq!(runs(&whole).len(), 6);
    assert_eq!(runs(&whole), runs(&all));
    // A shard missing, or one given twice: refused, naming it; nothing written.
    std::fs::remove_file(dir.join("all.json")).ok();
    for (files, says) in [
        (&["part-0.json", "part-1.json"][..], "shard 2/3 is missing"),
        (&["part-0.json", "part-0.json", "part-1.json"][..], "given twice"),
    ] {
        let out = merge(files);
        assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
        assert!(stderr(&out).contains(says), "{}", stderr(&out));
        assert!(!dir.join("all.json").exists());
    }
    std::fs::remove_dir_all(&dir).ok();
}
