//! `rinscope bench --only logs`: a 30-minute 100 Hz strapdown text log of a parked, rocked vehicle
//! (written by `export-log` into a scratch folder, its manifest cut down to what a field log has:
//! the IMU file and the start position), aligned on its own data and replayed in process: the
//! issue's target is under 1 s for both together.

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use super::{Figures, check, in_scratch};
use crate::scenario::logset;

/// The parked vehicle: a navigation-grade IMU at 100 Hz, rocked in pitch and roll, 30 minutes.
const PARKED: &str = r#"
[scenario]
name = "bench-parked"
title = "A parked vehicle rocked by wind, 30 min at 100 Hz"
seed = 7
[simulation]
duration_s = 1800.0
step_hz = 100.0
[site]
latitude_deg = 34.246048
longitude_deg = 108.909664
height_m = 380.0
[vehicle]
heading_deg = 269.4
[[vehicle.wobble]]
angle = "pitch"
amplitude_deg = 0.05
frequency_hz = 0.7
[[vehicle.wobble]]
angle = "roll"
amplitude_deg = 0.08
frequency_hz = 1.3
[turntable]
[[turntable.axis]]
name = "azimuth"
axis = "z"
[scheme]
kind = "static"
[imu]
algorithm = "two-sample"
[imu.gyro]
bias_deg_per_h = 0.01
arw_deg_per_sqrt_h = 0.001
[imu.accel]
bias_ug = 50.0
vrw_ug_per_sqrt_hz = 10.0
"#;

/// The field log's manifest: no table, no encoders, no reference, no start attitude.
const MANIFEST: &str = "[log]\nname = \"parked\"\n[imu]\nfile = \"imu.csv\"\nrate_hz = 100.0\n[initial]\nposition = [34.246048, 108.909664, 380.0]\n";

pub(super) fn log_speed(figs: &mut Figures, stop: &AtomicBool) -> anyhow::Result<()> {
    in_scratch("bench-logs", |dir| {
        let params = crate::scenario::parse(PARKED, "bench")?;
        let out = dir.join("parked");
        crate::app::export_log::export_log(&params, &out, crate::app::export_log::LogFormat::Csv, true, stop)?;
        for extra in ["table.toml", "encoders.csv", "reference.csv"] {
            std::fs::remove_file(out.join(extra)).ok();
        }
        std::fs::write(out.join(logset::MANIFEST), MANIFEST)?;
        let log = logset::load(&out)?;
        let bytes = std::fs::metadata(out.join("imu.csv"))?.len();
        let mut walls = Vec::new();
        let mut heading = 0.0;
        for _ in 0..5 {
            check(stop)?;
            let started = Instant::now();
            let s = crate::app::replay::replay(&log, &log.table.compensation, None, stop, None)?;
            walls.push(started.elapsed().as_secs_f64());
            heading = s.alignment.as_ref().map_or(f64::NAN, |a| a.imu_heading_deg);
        }
        walls.sort_by(f64::total_cmp);
        figs.figures.push(super::Figure {
            name: "field log/30 min 100 Hz csv, aligned + replayed".into(),
            value: walls[2],
            unit: "s",
            best: Some(walls[0]),
        });
        outln!(
            "field log         30 min at 100 Hz, strapdown csv ({:.1} MB), aligned on its first 300 s and replayed with navigation: best {:.3} s, median {:.3} s of 5 (target < 1 s; heading {heading:.4}°)",
            bytes as f64 / 1e6,
            walls[0],
            walls[2]
        );
        Ok(())
    })
}
