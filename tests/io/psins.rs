//! PSINS SIMU files (`.imu`): a writer that prints what PSINS's `imufile.m` prints, and the
//! psins-imu layout reading back the increments, times and header.
//!
//! Golden values: the increments are [`truth`] (smooth functions chosen here, each axis of one
//! sign so that its running sum never crosses zero). [`imufile_text`] quantises them as
//! `imufile.m` does, `diff(fix(cumsum(x ./ scale)))`, so every increment read back, and every
//! running sum, is within one count of the truth (plus the writer's g against the printed one,
//! below). The header numbers are what the MATLAB formats print: '%f' rounds to 6 decimals,
//! '%.8f' to 8, '%.3f' to 3.

use crate::common::*;
use rinscope::io::{
    Col, ColumnReader, Format, ImuOptions, ImuReader, ImuSample, Layout, PsinsHeader, ReadOptions, SampleKind,
    StartTime, detect_format, read_psins_header,
};
use std::path::Path;

pub use crate::psins_writer::{G_PRINTED, GLV_G0, SimuInput, imufile_text};

/// `n` increments at interval `ts`, sample k (from 1) at `t0 + k·ts + jitter_s(k)`: rates of one
/// sign per axis (rad/s, m/s²) times ts.
pub fn truth(n: usize, ts: f64, t0: f64, jitter_s: impl Fn(usize) -> f64) -> Vec<[f64; 7]> {
    (1..=n)
        .map(|k| {
            let t = k as f64 * ts;
            [
                (0.01 + 0.005 * (2.0 * t).sin()) * ts,
                (-0.02 + 0.003 * (5.0 * t).cos()) * ts,
                (0.002 + 0.001 * t.sin()) * ts,
                (0.1 + 0.05 * (3.0 * t).sin()) * ts,
                (-0.2 + 0.1 * t.sin()) * ts,
                (9.8 + 0.01 * (7.0 * t).cos()) * ts,
                t0 + t + jitter_s(k),
            ]
        })
        .collect()
}

/// The input of the tests: 5 s at 100 Hz from t0 = 1234.5 s; a yaw that '%f' rounds.
pub fn input(jitter_s: impl Fn(usize) -> f64) -> SimuInput {
    SimuInput {
        imu: truth(500, 0.01, 1234.5, jitter_s),
        avp0: [1.25, -2.5, 123.456_789_12, 0.5, -1.0, 0.0, 34.246_048, 108.909_664, 380.0, 1234.5],
        ts: 0.01,
        scales: [0.01, 0.02, 0.005, 1.0, 2.5, 0.5],
    }
}

/// The header [`input`] gives, as printed: yaw 123.45678912 → '%f' → 123.456789; g → 9.780327.
fn expected_header(has_dither: bool) -> PsinsHeader {
    PsinsHeader {
        pitch_deg: 1.25,
        roll_deg: -2.5,
        yaw_deg: 123.456_789,
        velocity_enu_mps: [0.5, -1.0, 0.0],
        latitude_deg: 34.246_048,
        longitude_deg: 108.909_664,
        height_m: 380.0,
        t0_s: 1234.5,
        interval_s: 0.01,
        g_mps2: G_PRINTED,
        gyro_scale_arcsec: [0.01, 0.02, 0.005],
        accel_scale_ug_s: [1.0, 2.5, 0.5],
        has_dither,
    }
}

/// Every increment, and every running sum, within one count of the truth: one count is
/// `gf·glv.sec` or `af·1e-6·g` (g as printed); the g the writer used differs by |9.780327/g0 − 1|
/// of the value.
fn assert_within_a_count(got: &[ImuSample], input: &SimuInput, header: &PsinsHeader) {
    assert_eq!(got.len(), input.imu.len());
    let count = header.count_scales();
    let g_rel = (G_PRINTED / GLV_G0 - 1.0).abs();
    let mut sums = [0.0; 6];
    let mut truth_sums = [0.0; 6];
    for (i, (s, r)) in got.iter().zip(&input.imu).enumerate() {
        let values = [s.gyro.x, s.gyro.y, s.gyro.z, s.accel.x, s.accel.y, s.accel.z];
        for k in 0..6 {
            let slack = if k < 3 { 1e-15 } else { g_rel * r[k].abs() + 1e-15 };
            assert!((values[k] - r[k]).abs() < count[k] + slack, "sample {i} column {k}: {} vs {}", values[k], r[k]);
            sums[k] += values[k];
            truth_sums[k] += r[k];
            let slack = if k < 3 { 1e-12 } else { g_rel * truth_sums[k].abs() + 1e-12 };
            assert!((sums[k] - truth_sums[k]).abs() < count[k] + slack, "running sum to {i}, column {k}");
        }
    }
}

fn read(path: &Path) -> (ImuReader, Vec<ImuSample>) {
    let reader = ImuReader::open(path, &ImuOptions::new(Layout::PsinsImu)).unwrap();
    let again = ImuReader::open(path, &ImuOptions::new(Layout::PsinsImu)).unwrap();
    (reader, samples(again))
}

#[test]
fn six_columns_round_trip() {
    let dir = scratch("psins_six");
    let input = input(|_| 0.0);
    let text = imufile_text(&input);
    let lines: Vec<&str> = text.lines().collect();
    // 13 comment lines and a blank one, the header rows on lines 15-17, a blank, data from 19.
    assert_eq!(lines[14], "1.250000 -2.500000 123.456789 0.500000 -1.000000 0.000000");
    assert_eq!(lines[15], "34.24604800 108.90966400 380.000 1234.50000000 10.00000000 9.780327");
    assert_eq!(lines[16], "0.010000 0.020000 0.005000 1.000 2.500 0.500");
    assert_eq!((lines[17], lines.len()), ("", 18 + 500));
    let path = write_text(&dir, "trj.imu", &text);
    assert_eq!(detect_format(&path).unwrap(), Format::PsinsImu);
    let header = read_psins_header(&path).unwrap();
    assert_eq!(header, expected_header(false));
    // Heading clockwise = -yaw wrapped: 360 − 123.456789.
    assert!((header.heading_deg() - 236.543_211).abs() < 1e-12);
    let (reader, got) = read(&path);
    assert_eq!(reader.kind(), SampleKind::Increments);
    assert_eq!(reader.psins_header(), Some(&header));
    assert_eq!(reader.nominal_dt_s(), Some(0.01));
    assert_eq!(reader.frame_to_rfu(), nalgebra::Matrix3::identity());
    assert_within_a_count(&got, &input, &header);
    // imufile.m: t = t0 + k·ts; relative to the first sample (k = 1), (k − 1)·ts.
    for (i, s) in got.iter().enumerate() {
        assert!((s.t_s - i as f64 * 0.01).abs() < 1e-9, "sample {i}: t {}", s.t_s);
    }
    let mut reader = reader;
    assert!(reader.next().is_some());
    assert_eq!(reader.start_time(), Some(StartTime::Seconds(1234.5 + 1.0 * 0.01)));
    // As a table: imufile.m's [wm vm t], t absolute.
    let cols: Vec<Col> = (0..7).map(Col::Index).collect();
    let mut table = ColumnReader::open(&path, &cols, &ReadOptions::default()).unwrap();
    assert_eq!(
        table.columns(),
        ["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad", "dv_x_mps", "dv_y_mps", "dv_z_mps", "t_s"]
    );
    assert_eq!(table.psins_header(), Some(&header));
    let mut row = [0.0; 7];
    assert!(table.next_row(&mut row).unwrap());
    assert_eq!((row[0], row[6]), (got[0].gyro.x, 1234.5 + 0.01));
    // A .txt (or any extension) is told by its first line too.
    let txt = write_text(&dir, "trj.txt", &text);
    assert_eq!(samples(ImuReader::open(&txt, &ImuOptions::new(Layout::PsinsImu)).unwrap()), got);
}

#[test]
fn seven_columns_with_dither() {
    let dir = scratch("psins_dither");
    // Sample k late by 3.7 µs × ((k mod 5) − 2): a dither imufile.m keeps to the µs (fix(t·1e6)).
    let jitter = |k: usize| 3.7e-6 * ((k % 5) as f64 - 2.0);
    let input = input(jitter);
    let text = imufile_text(&input);
    let path = write_text(&dir, "dither.imu", &text);
    let header = read_psins_header(&path).unwrap();
    assert_eq!(header, expected_header(true));
    assert!(text.lines().nth(14).unwrap().ends_with(" 0"));
    let (mut reader, got) = read(&path);
    assert_within_a_count(&got, &input, &header);
    // The file's own dt column (µs): t_k = t0 + k·ts + Σ_{j≤k} dt_j·1e-6.
    let dts: Vec<i64> = text.lines().skip(18).map(|l| l.rsplit(' ').next().unwrap().parse().unwrap()).collect();
    assert_eq!(dts.len(), 500);
    assert!(dts.iter().any(|&d| d != 0) && dts[0] == 0);
    let mut sum_us = 0;
    let first = 1234.5 + 0.01;
    for (i, s) in got.iter().enumerate() {
        sum_us += dts[i];
        let t = 1234.5 + (i + 1) as f64 * 0.01 + sum_us as f64 * 1e-6;
        assert!((s.t_s - (t - first)).abs() < 1e-9, "sample {i}");
        // Against the truth's stamps: fix() keeps them to 1 µs.
        let truth_t = input.imu[i][6] - input.imu[0][6];
        assert!((s.t_s - truth_t).abs() < 1e-6 + 1e-9, "sample {i}: {} vs {truth_t}", s.t_s);
    }
    assert!(reader.next().is_some());
    assert_eq!(reader.start_time(), Some(StartTime::Seconds(first)));
}

#[test]
fn seven_columns_of_zero_dither_read_as_six() {
    // imufile.m writes the dt column only when some dt is nonzero; its reader takes any 7-column
    // file. The 6-column text with ' 0' after every row of numbers reads to the same samples.
    let dir = scratch("psins_zero_dither");
    let text = imufile_text(&input(|_| 0.0));
    let six = write_text(&dir, "six.imu", &text);
    let seven_text: String = text
        .lines()
        .enumerate()
        .map(|(i, l)| if i >= 14 && !l.is_empty() { format!("{l} 0\n") } else { format!("{l}\n") })
        .collect();
    let seven = write_text(&dir, "seven.imu", &seven_text);
    assert!(read_psins_header(&seven).unwrap().has_dither);
    assert_eq!(read(&seven).1, read(&six).1);
}

#[test]
fn comments_anywhere_and_crlf() {
    // MATLAB's load: '%' starts a comment anywhere on a line; blank lines are skipped.
    let dir = scratch("psins_comments");
    let text = imufile_text(&input(|_| 0.0));
    let six = write_text(&dir, "six.imu", &text);
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    lines[20] += " % a note";
    lines.insert(25, "% a comment between the counts".into());
    lines.insert(26, "   ".into());
    let edited = write_text(&dir, "edited.imu", &(lines.join("\r\n") + "\r\n"));
    assert_eq!(read(&edited).1, read(&six).1);
}

#[test]
fn half_an_hour_at_100_hz_reads_fast() {
    // 30 min × 100 Hz = 180 000 lines; the release build must read them in well under 0.3 s.
    let dir = scratch("psins_large");
    let n = 180_000;
    let input = SimuInput { imu: truth(n, 0.01, 0.0, |_| 0.0), ..input(|_| 0.0) };
    let path = write_text(&dir, "long.imu", &imufile_text(&input));
    let started = std::time::Instant::now();
    let cpu_started = thread_cpu_s();
    let mut reader = ImuReader::open(&path, &ImuOptions::new(Layout::PsinsImu)).unwrap();
    let mut block = Vec::with_capacity(4096);
    let mut total = 0;
    let mut last_t = 0.0;
    loop {
        block.clear();
        let end = reader.next_samples(&mut block, 4096).unwrap();
        total += block.len();
        last_t = block.last().map_or(last_t, |s| s.t_s);
        if end == rinscope::io::BlockEnd::End {
            break;
        }
    }
    let wall = started.elapsed().as_secs_f64();
    // The reader's own time: the thread's CPU time where the system tells it (the other tests of
    // this binary share the cores and stretch the wall clock), else the wall clock.
    let cpu = thread_cpu_s().zip(cpu_started).map(|(end, start)| end - start);
    let elapsed = cpu.filter(|t| *t > 0.0).unwrap_or(wall);
    assert_eq!(total, n);
    assert!((last_t - (n - 1) as f64 * 0.01).abs() < 1e-9);
    eprintln!("psins-imu: {n} samples read in {elapsed:.3} s of CPU ({wall:.3} s wall)");
    if !cfg!(debug_assertions) {
        assert!(elapsed < 0.3, "{n} samples took {elapsed:.3} s");
    }
}

/// This thread's CPU time so far, s: Linux's /proc/thread-self/schedstat (ns on the CPU first);
/// None elsewhere.
fn thread_cpu_s() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    Some(text.split_whitespace().next()?.parse::<f64>().ok()? * 1e-9)
}
