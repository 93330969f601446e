//! Garbage, truncated and bit-flipped files of every format give errors, never panics.

use crate::common::*;
use rinscope::io::{Col, ColumnReader, Frame, ImuOptions, ImuReader, Layout, ReadOptions, TableWriter};
use std::path::Path;

/// A tiny deterministic generator (xorshift64*), so failures reproduce.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// Reads every column of every row; `Ok(rows)` or the first error.
fn read_all(path: &Path) -> rinscope::io::Result<usize> {
    let probe = ColumnReader::open(path, &[], &ReadOptions::default())?;
    let cols: Vec<Col> = (0..probe.all_columns().len()).map(Col::Index).collect();
    let mut reader = ColumnReader::open(path, &cols, &ReadOptions::default())?;
    let mut row = vec![0.0; cols.len()];
    let mut n = 0;
    while reader.next_row(&mut row)? {
        n += 1;
    }
    Ok(n)
}

/// Reads the file as an IMU log of its natural layout; `Ok(events)` or the first error.
fn read_imu(path: &Path, layout: Layout) -> rinscope::io::Result<usize> {
    let mut opts = ImuOptions::new(layout);
    opts.frame = Some(Frame::Named("rfu".into()));
    opts.gap_policy = rinscope::io::GapPolicy::Split;
    let reader = ImuReader::open(path, &opts)?;
    let mut n = 0;
    for e in reader {
        e?;
        n += 1;
    }
    Ok(n)
}

fn valid_files(dir: &Path) -> Vec<(std::path::PathBuf, Layout)> {
    let truth = truth_rates(30);
    let rows: Vec<Vec<f64>> =
        truth.iter().map(|s| vec![s.t_s, s.gyro.x, s.gyro.y, s.gyro.z, s.accel.x, s.accel.y, s.accel.z]).collect();
    let names = [
        "t_s",
        "gyro_x_rad_per_s",
        "gyro_y_rad_per_s",
        "gyro_z_rad_per_s",
        "accel_x_mps2",
        "accel_y_mps2",
        "accel_z_mps2",
    ];
    let mut out = Vec::new();
    for ext in ["csv", "npy", "parquet"] {
        let path = dir.join(format!("valid.{ext}"));
        let mut w = TableWriter::create(&path, &names).unwrap();
        for r in &rows {
            w.write_row(r).unwrap();
        }
        w.finish().unwrap();
        let layout =
            if ext == "npy" { Layout::Npy7 { time: rinscope::io::TimeUnit::Seconds } } else { Layout::Rinscope };
        out.push((path, layout));
    }
    let path = dir.join("valid.mcap");
    let messages = (0..30u32)
        .map(|i| (u64::from(i) * 10_000_000 + 1, cdr_imu(5, i * 10_000_000, "imu", [1e-5, 0.0, 0.0], [0.0, 0.0, 9.8])))
        .collect();
    write_mcap(&path, &[McapTopic { topic: "/imu", schema: "sensor_msgs/msg/Imu", messages }], true);
    out.push((path, Layout::Ros2));
    out
}

#[test]
fn truncated_files_are_errors() {
    let dir = scratch("garbage_truncated");
    for (path, layout) in valid_files(&dir) {
        let bytes = std::fs::read(&path).unwrap();
        assert!(read_all(&path).is_ok() && read_imu(&path, layout.clone()).is_ok(), "{path:?} should be valid");
        let ext = path.extension().unwrap().to_str().unwrap().to_owned();
        let cut_path = dir.join(format!("cut.{ext}"));
        let mut cuts: Vec<usize> = (0..bytes.len()).step_by(7).collect();
        cuts.extend([1, 4, 8, 9, 11, bytes.len() - 1]);
        for cut in cuts {
            if ext == "csv" {
                // A text table cut exactly at a line end is a valid shorter table; cut inside the
                // last line so that it loses at least one field separator.
                let last_nl = bytes[..cut].iter().rposition(|&b| b == b'\n');
                let tail_has_comma =
                    bytes[last_nl.map_or(0, |i| i + 1)..].iter().take_while(|&&b| b != b'\n').any(|&b| b == b',');
                let cut_has_all = bytes[last_nl.map_or(0, |i| i + 1)..cut].iter().filter(|&&b| b == b',').count() >= 6;
                if last_nl.is_none() || last_nl == Some(cut - 1) || !tail_has_comma || cut_has_all {
                    continue;
                }
            }
            std::fs::write(&cut_path, &bytes[..cut]).unwrap();
            let r =
                if ext == "csv" || ext == "mcap" { read_imu(&cut_path, layout.clone()) } else { read_all(&cut_path) };
            assert!(r.is_err(), "{ext} cut at {cut} of {} read as {r:?}", bytes.len());
        }
    }
}

#[test]
fn random_garbage_and_bit_flips_never_panic() {
    let dir = scratch("garbage_random");
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for (path, layout) in valid_files(&dir) {
        let bytes = std::fs::read(&path).unwrap();
        let ext = path.extension().unwrap().to_str().unwrap().to_owned();
        let bad = dir.join(format!("bad.{ext}"));
        // Magic followed by random bytes: always an error.
        let magic_len = match ext.as_str() {
            "npy" => 6,
            "parquet" => 4,
            "mcap" => 8,
            _ => 0,
        };
        for _ in 0..50 {
            let len = magic_len + rng.below(600);
            let mut g: Vec<u8> = bytes[..magic_len].to_vec();
            g.extend((magic_len..len).map(|_| rng.next() as u8));
            std::fs::write(&bad, &g).unwrap();
            let r = read_all(&bad);
            if ext != "csv" {
                assert!(r.is_err(), "{ext} garbage read as {r:?}");
            }
            let _ = read_imu(&bad, layout.clone());
        }
        // Bit flips and byte overwrites of a valid file: anything but a panic.
        for _ in 0..flips() {
            let mut g = bytes.clone();
            for _ in 0..1 + rng.below(4) {
                let i = rng.below(g.len());
                if rng.below(2) == 0 {
                    g[i] ^= 1 << rng.below(8);
                } else {
                    g[i] = rng.next() as u8;
                }
            }
            std::fs::write(&bad, &g).unwrap();
            let _ = read_all(&bad);
            let _ = read_imu(&bad, layout.clone());
        }
    }
}

/// Mutations per format: 1000, or LOGIO_FUZZ_ITERATIONS for a longer run.
fn flips() -> usize {
    std::env::var("LOGIO_FUZZ_ITERATIONS").ok().and_then(|v| v.parse().ok()).unwrap_or(1000)
}
