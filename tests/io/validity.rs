//! Issue 20 ("Trust, round 2"), at the readers: a last line cut inside its last number, a value
//! beyond any instrument, a first row that cannot be read, a positional layout asked of a file it
//! cannot read by position — each refused by the reader that meets it, naming the file, the row,
//! the column and the value in a short form.

use crate::common::*;
use rinscope::io::{
    BlockEnd, Col, ColumnReader, Frame, GapPolicy, ImuEvent, ImuOptions, ImuReader, Layout, LogError, ReadOptions,
    TimeUnit,
};
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

/// What a reader yields to its end: the samples, the gaps (as `(t_before_s, t_after_s)`) and the
/// first error's message, through `next_samples` (blocks: a block format's rows go through the
/// fast path) or through the iterator (one `step` per row, every check on every row).
type Yield = (Vec<rinscope::io::ImuSample>, Vec<(f64, f64)>, Option<String>);

fn read_all_ways(path: &Path, policy: GapPolicy) -> (Yield, Yield) {
    let mut options = ImuOptions::new(Layout::Npy7 { time: TimeUnit::Seconds });
    options.frame = Some(Frame::Named("frd".into()));
    options.gap_policy = policy;
    let gap_of = |e: ImuEvent| match e {
        ImuEvent::Gap { t_before_s, t_after_s, .. } => (t_before_s, t_after_s),
        ImuEvent::Sample(_) => unreachable!("a sample is not a gap"),
    };
    let mut blocks: Yield = (Vec::new(), Vec::new(), None);
    let mut r = ImuReader::open(path, &options).unwrap();
    loop {
        match r.next_samples(&mut blocks.0, 1000) {
            Ok(BlockEnd::Full) => {}
            Ok(BlockEnd::Gap(g)) => blocks.1.push(gap_of(g)),
            Ok(BlockEnd::End) => break,
            Err(e) => {
                blocks.2 = Some(e.to_string());
                break;
            }
        }
    }
    let mut rows: Yield = (Vec::new(), Vec::new(), None);
    for e in ImuReader::open(path, &options).unwrap() {
        match e {
            Ok(ImuEvent::Sample(s)) => rows.0.push(s),
            Ok(g) => rows.1.push(gap_of(g)),
            Err(e) => rows.2 = Some(e.to_string()),
        }
    }
    (blocks, rows)
}

/// Deep inside a block format (.npy, encoded here from the format's spec; read thousands of rows at
/// a time, where the reader checks a block's rows as plain comparisons), every defect is found at
/// the same row with the same message, every sample is the same number and every gap the same, as
/// when each row goes through the reader's full per-row checks: a NaN, a value beyond any
/// instrument, a stamp that goes back, a repeated stamp, a stamp off the clock, a gap (refused,
/// and split), and a clean file; in a frame that is not rinscope's (the axes turned).
#[test]
fn a_block_formats_rows_are_checked_as_row_by_row() {
    let dir = scratch("block_rows");
    let n = 9000;
    let clean: Vec<Vec<f64>> = (0..n)
        .map(|k| {
            let t = k as f64 * DT;
            vec![t, 1.5e-7 * (1.0 + t.sin()), -2.5e-7, 3.0e-7, 0.0316, -0.0021 * t.cos(), 0.098]
        })
        .collect();
    type Defect = fn(&mut [Vec<f64>]);
    let defects: [(&str, Defect, &str); 7] = [
        ("clean", |_| {}, ""),
        ("nan", |r| r[5000][2] = f64::NAN, "data row 5001"),
        ("beyond", |r| r[6100][5] = 1e6, "data row 6101"),
        ("backwards", |r| r[7000][0] = r[6990][0], "data row 7001"),
        ("repeated", |r| r[7000][0] = r[6999][0], "data row 7001"),
        ("off the clock", |r| r[8000][0] += 2e9, "data row 8001"),
        ("gap", |r| r[4500..].iter_mut().for_each(|row| row[0] += 1.0), "data row 4501"),
    ];
    for (name, defect, row) in defects {
        let mut rows = clean.clone();
        defect(&mut rows);
        let path = dir.join(format!("{}.npy", name.replace(' ', "_")));
        write_npy(&path, &rows, "<f8");
        for policy in [GapPolicy::Refuse, GapPolicy::Split] {
            let (blocks, by_row) = read_all_ways(&path, policy);
            assert_eq!(blocks, by_row, "{name}, {policy:?}");
            let split_gap = name == "gap" && policy == GapPolicy::Split;
            match &blocks.2 {
                Some(msg) => assert!(!split_gap && msg.contains(row), "{name}, {policy:?}: {msg}"),
                None => assert!(name == "clean" || split_gap, "{name}, {policy:?}: no error"),
            }
            // The samples before a defect: all of them, or (a NaN, which the file's reader refuses as
            // it decodes a block) those of the blocks before — the same both ways.
            let before = row.trim_start_matches("data row ").parse::<usize>().map_or(n, |r| r - 1);
            let kept = blocks.0.len();
            let whole = if blocks.2.is_some() { kept <= before && kept >= before - before % 4096 } else { kept == n };
            assert!(whole, "{name}, {policy:?}: {kept} samples before the defect");
            assert_eq!(blocks.1.len(), usize::from(split_gap), "{name}, {policy:?}: gaps");
        }
    }
}
