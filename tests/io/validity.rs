//! Issue 20 ("Trust, round 2"), at the readers: a last line cut inside its last number, a value
//! beyond any instrument, a first row that cannot be read, a positional layout asked of a file it
//! cannot read by position — each refused by the reader that meets it, naming the file, the row,
//! the column and the value in a short form.

use crate::common::*;
use rinscope::io::{Col, ColumnReader, Frame, ImuOptions, ImuReader, Layout, LogError, ReadOptions, TimeUnit};
use std::path::Path;

/// A rinscope csv of increments at 100 Hz: `rows` rows of plausible numbers, each cell as text.
fn increments_csv(rows: usize) -> Vec<Vec<String>> {
    (0..rows)
        .map(|k| {
            let t = k as f64 * DT;
            vec![
                format!("{t:.2}"),
                "1.5e-7".into(),
                "-2.5e-7".into(),
                "3.0e-7".into(),
                "0.0316".into(),
                "-0.0021".into(),
                "0.098".into(),
            ]
        })
        .collect()
}

fn csv_text(rows: &[Vec<String>]) -> String {
    let mut s = "t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps\n".to_owned();
    for r in rows {
        s.push_str(&r.join(","));
        s.push('\n');
    }
    s
}

/// Reads `path` as a rinscope IMU log to its end: the number of samples, or the first error.
fn read(path: &Path, layout: Layout) -> rinscope::io::Result<usize> {
    let mut options = ImuOptions::new(layout);
    options.frame = Some(Frame::Named("rfu".into()));
    let mut n = 0;
    for e in ImuReader::open(path, &options)? {
        e?;
        n += 1;
    }
    Ok(n)
}

fn message_of(e: &LogError, path: &Path, expected: &[&str]) {
    let msg = e.to_string();
    assert!(msg.starts_with(&path.display().to_string()), "{msg}");
    for piece in expected {
        assert!(msg.contains(piece), "{piece:?} not in: {msg}");
    }
    assert!(msg.len() < 600, "{} bytes: {msg}", msg.len());
}

#[test]
fn a_last_line_cut_inside_its_last_number_is_refused() {
    // Issue 20, item 3: "0.0316" → "0.0", no newline — every field is there and is a number.
    let dir = scratch("validity_cut");
    let mut rows = increments_csv(20);
    rows[19][6] = "0.0".into();
    let text = csv_text(&rows);
    let path = write_text(&dir, "cut.csv", text.trim_end_matches('\n'));
    let e = read(&path, Layout::Rinscope).unwrap_err();
    assert!(matches!(e, LogError::TruncatedLine { .. }), "{e:?}");
    message_of(&e, &path, &["data row 20 (line 21)", "no line end", "truncated"]);
    // Any table read through the column reader (an encoder or reference file) says the same.
    let mut r = ColumnReader::open(&path, &[Col::from("t_s"), Col::from("dv_z_mps")], &ReadOptions::default()).unwrap();
    let mut row = [0.0; 2];
    let e = loop {
        match r.next_row(&mut row) {
            Ok(true) => {}
            Ok(false) => panic!("read to the end"),
            Err(e) => break e,
        }
    };
    assert!(matches!(e, LogError::TruncatedLine { at, .. } if at.row == 20), "{e:?}");
    // The same file with its line end reads, every row.
    let path = write_text(&dir, "whole.csv", &text);
    assert_eq!(read(&path, Layout::Rinscope).unwrap(), 20);
}

#[test]
fn one_value_beyond_any_instrument_is_refused_where_it_is() {
    // Issue 20, item 6: one finite but absurd value (1e300) turned the attitude into NaN.
    let dir = scratch("validity_bounds");
    let mut rows = increments_csv(20);
    rows[6][2] = "1e300".into();
    let path = write_text(&dir, "absurd.csv", &csv_text(&rows));
    let e = read(&path, Layout::Rinscope).unwrap_err();
    message_of(&e, &path, &["data row 7 (line 8)", "column dtheta_y_rad", "\"1e300\"", "gyro", "100 rev/s"]);
    // A velocity increment of 1000 g over 10 ms is 98 m/s: 150 m/s is beyond it, 90 m/s is not.
    for (value, refused) in [("150", true), ("90", false), ("-1e30", true)] {
        let mut rows = increments_csv(20);
        rows[3][4] = value.into();
        let path = write_text(&dir, "dv.csv", &csv_text(&rows));
        match read(&path, Layout::Rinscope) {
            Ok(n) => assert!(!refused && n == 20, "{value}: read"),
            Err(e) => {
                assert!(refused, "{value}: {e}");
                message_of(&e, &path, &["data row 4 (line 5)", "column dv_x_mps", "accelerometer", "1000 g"]);
            }
        }
    }
    // Rates in deg/s: 30 000 °/s (83 rev/s) is a gyro's, 1e5 °/s (278 rev/s) is none's.
    let rates = |gx: &str| {
        let mut s = "t_s,gyro_x_deg_per_s,gyro_y_deg_per_s,gyro_z_deg_per_s,accel_x_g,accel_y_g,accel_z_g\n".to_owned();
        for k in 0..20 {
            s.push_str(&format!("{:.2},{},0.1,0.2,0.0,0.0,1.0\n", k as f64 * DT, if k == 9 { gx } else { "0.5" }));
        }
        s
    };
    let path = write_text(&dir, "rates.csv", &rates("30000"));
    assert_eq!(read(&path, Layout::Rinscope).unwrap(), 20);
    let path = write_text(&dir, "rates.csv", &rates("1e5"));
    let e = read(&path, Layout::Rinscope).unwrap_err();
    message_of(&e, &path, &["data row 10 (line 11)", "column gyro_x_deg_per_s", "\"100000\"", "rad/s"]);
    // A time stamp of 1e300 s: short, and named as a time.
    let mut rows = increments_csv(20);
    rows[19][0] = "1e300".into();
    let path = write_text(&dir, "time.csv", &csv_text(&rows));
    let e = read(&path, Layout::Rinscope).unwrap_err();
    message_of(&e, &path, &["data row 20 (line 21)", "column t_s", "\"1e300\"", "same clock"]);
    // NaN is not "an IMU log's" problem only: the column reader's message fits any file.
    let mut rows = increments_csv(20);
    rows[2][1] = "NaN".into();
    let path = write_text(&dir, "nan.csv", &csv_text(&rows));
    let e = read(&path, Layout::Rinscope).unwrap_err();
    message_of(&e, &path, &["data row 3 (line 4)", "dtheta_x_rad", "NaN", "finite"]);
    assert!(!e.to_string().contains("IMU log"), "{e}");
}

#[test]
fn a_reader_reports_its_own_first_error() {
    // Issue 20, item 7: a failure on the first read was "no IMU samples" one level up.
    let dir = scratch("validity_first");
    let mut text = csv_text(&increments_csv(20));
    text = text.replacen("0.00,1.5e-7,-2.5e-7,3.0e-7,0.0316,", "0.00,1.5e-7,", 1);
    let path = write_text(&dir, "short.csv", &text);
    let e = ImuReader::open(&path, &ImuOptions::new(Layout::Rinscope)).unwrap_err();
    message_of(&e, &path, &["data row 1 (line 2)", "4 fields", "header has 7"]);
    // An MCAP whose first (only) chunk is corrupt: the chunk's error, at open.
    let messages: Vec<(u64, Vec<u8>)> = (0..200)
        .map(|k| {
            (
                1_000_000_000 + k * 10_000_000,
                cdr_imu(1, (k * 10_000_000) as u32, "imu", [0.01, 0.02, 0.03], [0.0, 0.0, 9.8]),
            )
        })
        .collect();
    let path = dir.join("corrupt.mcap");
    write_mcap(&path, &[McapTopic { topic: "/imu", schema: "sensor_msgs/msg/Imu", messages }], true);
    let mut bytes = std::fs::read(&path).unwrap();
    let middle = bytes.len() / 3;
    bytes[middle] ^= 0x5a;
    std::fs::write(&path, &bytes).unwrap();
    let e = ImuReader::open(&path, &ImuOptions::new(Layout::Ros2)).unwrap_err();
    let msg = e.to_string();
    assert!(msg.starts_with(&path.display().to_string()) && !msg.contains("no IMU samples"), "{msg}");
}

#[test]
fn positional_layouts_refuse_files_they_cannot_read_by_position() {
    // Issue 20, item 9: `layout = "kalibr"` on a rinscope csv said "the file holds rates (its
    // columns … dtheta_x_rad …)"; the rinscope layout read an .mcap as ROS 2 without a word.
    let dir = scratch("validity_positional");
    let path = write_text(&dir, "imu.csv", &csv_text(&increments_csv(20)));
    for layout in [Layout::Kalibr, Layout::Npy7 { time: TimeUnit::Seconds }, Layout::Psins] {
        let e = read(&path, layout.clone()).unwrap_err();
        message_of(
            &e,
            &path,
            &[
                "rinscope columns",
                "dtheta_x_rad",
                &format!("layout = \"{}\"", layout.name()),
                "use layout = \"rinscope\"",
            ],
        );
        assert!(!e.to_string().contains("holds rates"), "{e}");
    }
    let messages = vec![(1_000_000_000, cdr_imu(1, 0, "imu", [0.0; 3], [0.0, 0.0, 9.8]))];
    let mcap = dir.join("imu.mcap");
    write_mcap(&mcap, &[McapTopic { topic: "/imu", schema: "sensor_msgs/msg/Imu", messages }], true);
    let e = read(&mcap, Layout::Rinscope).unwrap_err();
    message_of(&e, &mcap, &["MCAP", "layout = \"ros2\""]);
}

#[test]
fn bytes_after_a_files_end_are_refused() {
    // Issue 20, item 8: a second file appended after an MCAP's closing magic, or two Parquet files
    // joined with `cat` (the second's footer then reads the first's bytes), read as if whole.
    let dir = scratch("validity_after_end");
    let messages: Vec<(u64, Vec<u8>)> = (0..50)
        .map(|k| {
            (
                1_000_000_000 + k * 10_000_000,
                cdr_imu(1, (k * 10_000_000) as u32, "imu", [0.01, 0.02, 0.03], [0.0, 0.0, 9.8]),
            )
        })
        .collect();
    let mcap = dir.join("imu.mcap");
    write_mcap(&mcap, &[McapTopic { topic: "/imu", schema: "sensor_msgs/msg/Imu", messages }], true);
    assert_eq!(read(&mcap, Layout::Ros2).unwrap(), 50);
    let whole = std::fs::read(&mcap).unwrap();
    for (case, tail) in [("garbage", b"\x00\x01 not mcap".to_vec()), ("twice", whole.clone())] {
        let path = dir.join(format!("{case}.mcap"));
        std::fs::write(&path, [whole.clone(), tail].concat()).unwrap();
        let e = read(&path, Layout::Ros2).unwrap_err();
        message_of(&e, &path, &["bytes follow the recording's closing magic", &format!("at byte {}", whole.len())]);
    }
    let rows: Vec<Vec<f64>> = truth_increments(100)
        .iter()
        .map(|s| vec![s.t_s, s.gyro.x, s.gyro.y, s.gyro.z, s.accel.x, s.accel.y, s.accel.z])
        .collect();
    let names = ["t_s", "dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad", "dv_x_mps", "dv_y_mps", "dv_z_mps"];
    let parquet = dir.join("imu.parquet");
    write_parquet(&parquet, &names, &rows, None, 40);
    assert_eq!(read(&parquet, Layout::Rinscope).unwrap(), 100);
    let joined = dir.join("joined.parquet");
    let bytes = std::fs::read(&parquet).unwrap();
    std::fs::write(&joined, [bytes.clone(), bytes].concat()).unwrap();
    let e = read(&joined, Layout::Rinscope).unwrap_err();
    message_of(&e, &joined, &["nothing refers to them", "two Parquet files joined"]);
}
