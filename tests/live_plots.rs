//! Every plot shows its data, live or not (issue 22): a live session's recording and a run's are
//! read back, and for every time-series view of the layout the recording ends with, its data must
//! exist (the INS plots were NaN in every live session) and lie inside the value range the
//! layout gives it (a fixed range hid series; the viewer kept ±1 for plots created before data).

mod common;
use common::scratch;
use std::path::Path;
use std::process::Command;

use rinscope::record::read::{PlotFrame, plot_frames};

fn check(rec: &Path, what: &str) -> Vec<PlotFrame> {
    let frames = plot_frames(rec).expect("readable recording");
    assert!(!frames.is_empty(), "{what}: no plots");
    for f in &frames {
        assert!(f.finite > 0, "{what}: the plot {:?} ({}) has no finite data", f.title, f.origin);
        if let Some([lo, hi]) = f.range {
            assert!(
                f.min >= lo && f.max <= hi,
                "{what}: {:?} shows [{lo}, {hi}] but its data span [{}, {}]",
                f.title,
                f.min,
                f.max
            );
        }
    }
    frames
}

#[test]
fn every_plot_of_a_live_session_and_of_a_run_shows_its_data() {
    for scenario in ["pure-coning", "jiang2017-dual-axis"] {
        let dir = scratch(scenario);
        let rec = dir.join("live.rrd");
        let o = Command::new(env!("CARGO_BIN_EXE_rinscope"))
            .current_dir(&dir)
            .args([
                "live",
                "--scenario",
                scenario,
                "--no-viewer",
                "--no-panel",
                "--speed",
                "40",
                "--duration-s",
                "60",
                "--export-format",
                "csv",
                "--export",
                "tables",
                "--save",
            ])
            .arg(&rec)
            .output()
            .expect("run");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        // The session's series are exported when it ends (live --export was listed and refused).
        let table = std::fs::read_to_string(dir.join("tables/gimbal_angle_deg.csv"))
            .expect("the live session's gimbal angles exported");
        assert!(table.lines().count() > 100, "{} rows", table.lines().count());
        let frames = check(&rec, &format!("live {scenario}"));
        if scenario == "pure-coning" {
            // The three INS attitude-error plots, framed on their data.
            let ins: Vec<&PlotFrame> =
                frames.iter().filter(|f| f.origin.starts_with("ins/attitude_error_arcsec/")).collect();
            assert_eq!(ins.len(), 3, "{frames:?}");
            assert!(ins.iter().all(|f| f.range.is_some() && f.non_finite == 0), "{ins:?}");
            let heading =
                std::fs::read_to_string(dir.join("tables/ins__attitude_error_arcsec__heading.csv")).expect("INS table");
            let last: Vec<f64> =
                heading.lines().last().expect("rows").split(',').map(|v| v.parse().expect("number")).collect();
            // The single-sample algorithm's heading drift after 60 s: hundreds of arcsec (docs/coning.md's rate).
            assert!(last[1..].iter().all(|v| v.is_finite()) && last[1].abs() > 100.0, "{last:?}");
        }
        let run = dir.join("run.rrd");
        let o = Command::new(env!("CARGO_BIN_EXE_rinscope"))
            .current_dir(&dir)
            .args(["run", "--scenario", scenario, "--duration-s", "60", "--save"])
            .arg(&run)
            .output()
            .expect("run");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        check(&run, &format!("run {scenario}"));
        std::fs::remove_dir_all(&dir).ok();
    }
}
