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
    Col, ColumnReader, Format, ImuOptions, ImuReader, ImuSample, Layout, PsinsHeader, ReadOptions,
    SampleKind, StartTime, detect_format, read_psins_header,
};
use std::path::Path;

/// PSINS `glvs.m`: `glv.g0 = 9.7803267714`. The writer scales the accelerometer counts by
/// `glv.ug = 1e-6*glv.g0` and prints `glv.g0` with '%f' (9.780327), which the reader then uses:
/// a relative difference of 3.3e-8 that the tolerances below allow for.
pub const GLV_G0: f64 = 9.780_326_771_4;
/// `glvs.m`: `glv.deg = pi/180; glv.min = glv.deg/60; glv.sec = glv.min/60`.
pub const GLV_SEC: f64 = std::f64::consts::PI / 180.0 / 60.0 / 60.0;
/// The g header row 2 carries: `sprintf('%f', glv.g0)`.
const G_PRINTED: f64 = 9.780_327;

/// What `imufile(fname, imu, avp0, ts, scales, infostr)` is given, with the attitude and
/// latitude/longitude already in degrees (what its `r2d` prints).
#[derive(Clone)]
pub struct SimuInput {
    /// `imu = [wm vm t]`: increments (rad, m/s) over the previous sample and sample times (s).
    pub imu: Vec<[f64; 7]>,
    /// `[pitch roll yaw (deg), VE VN VU (m/s), lat lon (deg), h (m), t0 (s)]`, t0 >= 0.
    pub avp0: [f64; 10],
    /// Sampling interval, s.
    pub ts: f64,
    /// `[gf_x gf_y gf_z (arcsec), af_x af_y af_z (ug*s)]`.
    pub scales: [f64; 6],
}

/// The text `imufile.m`'s write branch produces for `input`, statement by statement.
pub fn imufile_text(input: &SimuInput) -> String {
    let SimuInput { imu, avp0, ts, scales: s0 } = input;
    let ts = *ts;
    // scales = [scales(1:3)*glv.sec, scales(4:6)*glv.ug];
    let ug = 1e-6 * GLV_G0;
    let scales = [s0[0] * GLV_SEC, s0[1] * GLV_SEC, s0[2] * GLV_SEC, s0[3] * ug, s0[4] * ug, s0[5] * ug];
    // t = imu(:,7)-imu(1,7)+ts+avp0(end); t = t - (1:length(t))'*ts; t = [0;diff(fix(t*1e6))];
    let t1 = imu.first().map_or(0.0, |r| r[6]);
    let fixed_us: Vec<i64> = imu
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let t = r[6] - t1 + ts + avp0[9];
            ((t - (i + 1) as f64 * ts) * 1e6).trunc() as i64
        })
        .collect();
    let dither: Vec<i64> = std::iter::once(0).chain(fixed_us.windows(2).map(|w| w[1] - w[0])).collect();
    // imu(:,k) = imu(:,k)/scales(k); imu = diff([zeros(1,6); fix(cumsum(imu,1))]);
    let mut sums = [0.0; 6];
    let mut before = [0i64; 6];
    let counts: Vec<[i64; 6]> = imu
        .iter()
        .map(|r| {
            let mut c = [0; 6];
            for k in 0..6 {
                sums[k] += r[k] / scales[k];
                let fixed = sums[k].trunc() as i64;
                c[k] = fixed - before[k];
                before[k] = fixed;
            }
            c
        })
        .collect();
    // print_header(fid, infostr), with datestr(now,31) fixed for the test.
    let mut text = String::from(concat!(
        "% PSINS-format SIMU log file. (DO NOT MODIFY!)\n",
        "% 2024-05-06 07:08:09  by Gongmin Yan\n",
        "% 1st line of the data header includes(maybe inaccurate):\n",
        "%   [pitch0(deg), roll0(deg), yaw0(deg), VE0(m/s), VN0(m/s), VU0(m/s)].\n",
        "% 2nd line of the data includes:\n",
        "%   [latitude0(deg), longitude0(deg), height0(m), t0(s), sampling-interval(ms), g(m/s^2)].\n",
        "% 3rd line of the data header includes:\n",
        "%   [gf_x, gf_y, gf_z, af_x, af_y, af_z]\n",
        "%   where gf_* is gyro scale factor in arcsec, af_* is acc scale factor in ug*s.\n",
        "% SIMU data columns include:\n",
        "%   [g_x, g_y, g_z, a_x, a_y, a_z, dt]\n",
        "%   where dt, if exists, is sampling time dither in millisecond.\n",
        "%   Conventionally, SIMU is mounted on vehicle with \"x-Right,y-Forward,z-Up\" orientations.\n\n",
    ));
    // if sum(abs(t))>0: the 7-column form, every header row ending in ' 0'.
    let seven = dither.iter().any(|&d| d != 0);
    let end = if seven { " 0" } else { "" };
    let a = avp0;
    text += &format!("{:.6} {:.6} {:.6} {:.6} {:.6} {:.6}{end}\n", a[0], a[1], a[2], a[3], a[4], a[5]);
    text += &format!("{:.8} {:.8} {:.3} {:.8} {:.8} {:.6}{end}\n", a[6], a[7], a[8], a[9], ts * 1000.0, GLV_G0);
    text += &format!("{:.6} {:.6} {:.6} {:.3} {:.3} {:.3}{end}\n\n", s0[0], s0[1], s0[2], s0[3], s0[4], s0[5]);
    for (c, d) in counts.iter().zip(&dither) {
        text += &format!("{} {} {} {} {} {}", c[0], c[1], c[2], c[3], c[4], c[5]);
        text += &if seven { format!(" {d}\n") } else { "\n".to_owned() };
    }
    text
}

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
    assert_eq!(table.columns(), ["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad", "dv_x_mps", "dv_y_mps", "dv_z_mps", "t_s"]);
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
