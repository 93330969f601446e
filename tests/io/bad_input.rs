//! Each bad input gives the right error, naming the file (and row, line, column, value where they apply).

use crate::common::*;
use rinscope::io::{
    Col, ColumnReader, Frame, GapPolicy, ImuEvent, ImuOptions, ImuReader, Layout, Location, LogError, ReadOptions,
    StaticCheck,
};
use std::path::Path;

const HEADER: &str = "t_s,gyro_x_rad_per_s,gyro_y_rad_per_s,gyro_z_rad_per_s,accel_x_mps2,accel_y_mps2,accel_z_mps2";

/// The error's message starts with the file's path.
fn names_file(e: &LogError, path: &Path) -> String {
    let msg = e.to_string();
    assert!(msg.starts_with(&path.display().to_string()), "message does not start with the file: {msg}");
    assert_eq!(e.file(), path);
    msg
}

fn rates_csv(times: &[f64]) -> String {
    let mut text = format!("{HEADER}\n");
    for t in times {
        text += &format!("{t},1e-5,2e-5,3e-5,0.01,0.02,9.81\n");
    }
    text
}

/// Runs the reader to its end; the first error.
fn first_error(path: &Path, opts: &ImuOptions) -> LogError {
    match ImuReader::open(path, opts) {
        Err(e) => e,
        Ok(reader) => reader.filter_map(Result::err).next().expect("an error"),
    }
}

#[test]
fn missing_column_lists_what_exists() {
    let dir = scratch("missing_column");
    let path = write_text(&dir, "a.csv", &rates_csv(&[0.0, 0.01]));
    let e = ColumnReader::open(&path, &[Col::from("t_s"), Col::from("gyro_q")], &ReadOptions::default()).unwrap_err();
    let msg = names_file(&e, &path);
    assert!(
        matches!(&e, LogError::MissingColumn { column, available, .. } if column == "\"gyro_q\"" && available.len() == 7),
        "{e:?}"
    );
    assert!(msg.contains("\"accel_z_mps2\" (index 6)"), "{msg}");
    let e = ColumnReader::open(&path, &[Col::Index(9)], &ReadOptions::default()).unwrap_err();
    assert!(matches!(e, LogError::MissingColumn { .. }));
    // The IMU layout names the missing axis.
    let path =
        write_text(&dir, "b.csv", &rates_csv(&[0.0]).replace(",accel_z_mps2", ",temp_c").replace("9.81\n", "20\n"));
    let e = ImuReader::open(&path, &ImuOptions::new(Layout::Rinscope)).unwrap_err();
    assert!(matches!(&e, LogError::MissingColumn { column, .. } if column.starts_with("accel_z_<unit>")), "{e}");
}

#[test]
fn wrong_and_unknown_unit_names() {
    let dir = scratch("units_bad");
    let path = write_text(&dir, "a.csv", &rates_csv(&[0.0]).replace("gyro_y_rad_per_s", "gyro_y_rad"));
    let e = ImuReader::open(&path, &ImuOptions::new(Layout::Rinscope)).unwrap_err();
    let msg = names_file(&e, &path);
    assert!(matches!(&e, LogError::Unit { column, .. } if column == "gyro_y_rad"), "{e:?}");
    assert!(msg.contains("an angular rate") && msg.contains("_deg_per_h"), "{msg}");
    let path = write_text(&dir, "b.csv", &rates_csv(&[0.0]).replace("accel_x_mps2", "accel_x_fps2"));
    let e = ImuReader::open(&path, &ImuOptions::new(Layout::Rinscope)).unwrap_err();
    assert!(e.to_string().contains("unknown unit \"fps2\""), "{e}");
}

#[test]
fn non_monotonic_and_duplicated_stamps() {
    let dir = scratch("time_order");
    let path = write_text(&dir, "back.csv", &rates_csv(&[0.0, 0.01, 0.02, 0.015, 0.03]));
    let e = first_error(&path, &ImuOptions::new(Layout::Rinscope));
    let msg = names_file(&e, &path);
    match &e {
        LogError::NonMonotonicTime { at, t_prev, t, column, .. } => {
            // Data row 4 is file line 5 (one header line).
            assert_eq!(*at, Location { row: 4, line: Some(5) });
            assert_eq!((t_prev.as_str(), t.as_str(), column.as_str()), ("0.02 s", "0.015 s", "t_s"));
        }
        other => panic!("{other:?}"),
    }
    assert!(msg.contains("0.015 s after 0.02 s"), "{msg}");
    let path = write_text(&dir, "dup.csv", &rates_csv(&[0.0, 0.01, 0.01, 0.02]));
    let e = first_error(&path, &ImuOptions::new(Layout::Rinscope));
    assert!(matches!(&e, LogError::DuplicateTime { at: Location { row: 3, .. }, t, .. } if t == "0.01 s"), "{e:?}");
    // Integer nanosecond stamps are compared exactly: 1 ns apart is no duplicate.
    let ns = format!("{}\n{T0_NS},0,0,0,0,0,9.8\n{},0,0,0,0,0,9.8\n", HEADER.replace("t_s", "t_ns"), T0_NS + 1);
    let path = write_text(&dir, "ns.csv", &ns);
    assert_eq!(samples(ImuReader::open(&path, &ImuOptions::new(Layout::Rinscope)).unwrap()).len(), 2);
}

#[test]
fn gaps_refused_or_split() {
    let dir = scratch("gaps");
    let mut times: Vec<f64> = (0..20).map(|i| f64::from(i) * 0.01).collect();
    times.extend((0..10).map(|i| 0.5 + f64::from(i) * 0.01));
    let path = write_text(&dir, "gap.csv", &rates_csv(&times));
    let e = first_error(&path, &ImuOptions::new(Layout::Rinscope));
    names_file(&e, &path);
    match e {
        LogError::Gap { at, t_before_s, t_after_s, gap_s, nominal_s, .. } => {
            assert_eq!(at.row, 21);
            assert!((t_before_s - 0.19).abs() < 1e-12 && (t_after_s - 0.5).abs() < 1e-12);
            assert!((gap_s - 0.31).abs() < 1e-12 && (nominal_s - 0.01).abs() < 1e-12);
        }
        other => panic!("{other:?}"),
    }
    let mut opts = ImuOptions::new(Layout::Rinscope);
    opts.gap_policy = GapPolicy::Split;
    let events: Vec<ImuEvent> = ImuReader::open(&path, &opts).unwrap().map(Result::unwrap).collect();
    assert_eq!(events.len(), 31);
    assert!(
        matches!(events[20], ImuEvent::Gap { at: Location { row: 21, .. }, t_before_s, .. } if (t_before_s - 0.19).abs() < 1e-12)
    );
    assert!(matches!(events[21], ImuEvent::Sample(s) if (s.t_s - 0.5).abs() < 1e-12));
}

#[test]
fn nan_rows_and_non_numeric_cells() {
    let dir = scratch("nan");
    let text = rates_csv(&[0.0, 0.01, 0.02]).replacen("0.01,1e-5,2e-5", "0.01,1e-5,NaN", 1);
    let path = write_text(&dir, "nan.csv", &text);
    let e = first_error(&path, &ImuOptions::new(Layout::Rinscope));
    let msg = names_file(&e, &path);
    assert!(
        matches!(&e, LogError::NonFinite { at: Location { row: 2, line: Some(3) }, column, value, .. } if column == "gyro_y_rad_per_s" && value == "NaN"),
        "{e:?}"
    );
    assert!(msg.contains("data row 2 (line 3)"), "{msg}");
    let path = dir.join("nan.npy");
    write_npy(&path, &[vec![0.0, 1.0], vec![0.01, f64::INFINITY]], "<f8");
    let mut reader = ColumnReader::open(&path, &[Col::Index(0), Col::Index(1)], &ReadOptions::default()).unwrap();
    let mut row = [0.0; 2];
    assert!(reader.next_row(&mut row).unwrap());
    assert!(matches!(reader.next_row(&mut row), Err(LogError::NonFinite { at: Location { row: 2, line: None }, .. })));
    let text = rates_csv(&[0.0, 0.01]).replacen("0.01,1e-5", "0.01,1e-5x", 1);
    let path = write_text(&dir, "text.csv", &text);
    let e = first_error(&path, &ImuOptions::new(Layout::Rinscope));
    assert!(
        matches!(&e, LogError::NonNumeric { column, value, .. } if column == "gyro_x_rad_per_s" && value == "1e-5x"),
        "{e:?}"
    );
}

#[test]
fn truncated_last_line() {
    let dir = scratch("truncated_line");
    let mut text = rates_csv(&[0.0, 0.01, 0.02]);
    text += "0.03,1e-5,2e-5";
    let path = write_text(&dir, "cut.csv", &text);
    let e = first_error(&path, &ImuOptions::new(Layout::Rinscope));
    let msg = names_file(&e, &path);
    assert!(
        matches!(
            e,
            LogError::FieldCount {
                at: Location { row: 4, line: Some(5) },
                expected: 7,
                found: 3,
                truncated_last_line: true,
                ..
            }
        ),
        "{e:?}"
    );
    assert!(msg.contains("truncated"), "{msg}");
    // A short row in the middle is not called truncated.
    let text = rates_csv(&[0.0, 0.01, 0.02]).replacen("0.01,1e-5,2e-5,3e-5,", "0.01,1e-5,", 1);
    let path = write_text(&dir, "short.csv", &text);
    let e = first_error(&path, &ImuOptions::new(Layout::Rinscope));
    assert!(matches!(e, LogError::FieldCount { truncated_last_line: false, .. }), "{e:?}");
}

#[test]
fn file_is_not_what_its_extension_says() {
    let dir = scratch("not_format");
    let path = write_text(&dir, "data.npy", &rates_csv(&[0.0]));
    let e = ColumnReader::open(&path, &[], &ReadOptions::default()).unwrap_err();
    let msg = names_file(&e, &path);
    assert!(matches!(e, LogError::NotTheFormat { .. }), "{e:?}");
    assert!(msg.contains("NumPy") && msg.contains("text"), "{msg}");
    let npy = dir.join("real.npy");
    write_npy(&npy, &[vec![1.0]], "<f8");
    for name in ["npy_named.csv", "npy_named.parquet", "npy_named.mcap"] {
        let path = dir.join(name);
        std::fs::copy(&npy, &path).unwrap();
        let e = ColumnReader::open(&path, &[], &ReadOptions::default()).unwrap_err();
        assert!(matches!(e, LogError::NotTheFormat { .. }), "{name}: {e:?}");
    }
    // A Parquet file cut short: the PAR1 footer is missing.
    let pq = dir.join("t.parquet");
    write_parquet(&pq, &["t_s"], &[vec![0.0], vec![1.0]], None, 10);
    let bytes = std::fs::read(&pq).unwrap();
    std::fs::write(&pq, &bytes[..bytes.len() - 10]).unwrap();
    let e = ColumnReader::open(&pq, &[], &ReadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("truncated"), "{e}");
}

#[test]
fn npy_dtype_and_shape() {
    let dir = scratch("npy_bad");
    let path = dir.join("i8.npy");
    write_npy(&path, &[vec![1.0, 2.0]], "<i8");
    let e = ColumnReader::open(&path, &[], &ReadOptions::default()).unwrap_err();
    names_file(&e, &path);
    assert!(matches!(&e, LogError::NpyDtype { dtype, .. } if dtype == "<i8"), "{e:?}");
    // 1-D and 3-D shapes.
    for (shape, n) in [("(4,)", 4), ("(2, 2, 1)", 4)] {
        let dict = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': {shape}, }}");
        let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
        bytes.extend(u16::try_from(dict.len() + 1).unwrap().to_le_bytes());
        bytes.extend(dict.as_bytes());
        bytes.push(b'\n');
        bytes.extend(std::iter::repeat_n(0u8, 8 * n));
        let path = dir.join("shape.npy");
        std::fs::write(&path, bytes).unwrap();
        let e = ColumnReader::open(&path, &[], &ReadOptions::default()).unwrap_err();
        assert!(matches!(e, LogError::Shape { .. }), "{shape}: {e:?}");
    }
    // Npy7 on an N×6 or N×8 array (issue 20: an 8-column array was read as its first 7): an .npy
    // has no names to tell which column is missing or extra, so the width itself is refused.
    let mut opts = ImuOptions::new(Layout::Npy7 { time: rinscope::io::TimeUnit::Seconds });
    opts.frame = Some(Frame::Named("rfu".into()));
    for width in [6, 8] {
        let path = dir.join(format!("w{width}.npy"));
        write_npy(&path, &[vec![0.0; width], vec![0.005; width]], "<f8");
        let e = ImuReader::open(&path, &opts).unwrap_err();
        let msg = e.to_string();
        assert!(
            matches!(e, LogError::Shape { .. }) && msg.contains(&format!("(N, {width})")) && msg.contains("7 columns"),
            "{msg}"
        );
    }
}

#[test]
fn unreadable_files() {
    let dir = scratch("unreadable");
    let missing = dir.join("nope.csv");
    let e = ColumnReader::open(&missing, &[], &ReadOptions::default()).unwrap_err();
    names_file(&e, &missing);
    assert!(matches!(e, LogError::Io { .. }));
    let as_dir = dir.join("adir.csv");
    std::fs::create_dir(&as_dir).unwrap();
    assert!(matches!(ColumnReader::open(&as_dir, &[], &ReadOptions::default()).unwrap_err(), LogError::Io { .. }));
    let empty = write_text(&dir, "empty.csv", "");
    assert!(ColumnReader::open(&empty, &[], &ReadOptions::default()).is_err());
}

fn static_opts(layout: Layout) -> ImuOptions {
    let mut o = ImuOptions::new(layout);
    o.static_check = Some(StaticCheck { duration_s: 1.0, ..StaticCheck::default() });
    o
}

#[test]
fn plausibility_catches_wrong_kind_and_units() {
    let dir = scratch("plausible");
    let times: Vec<f64> = (0..300).map(|i| f64::from(i) * 0.005).collect(); // 200 Hz, 1.5 s
    // Rates (m/s², rad/s) under increment names.
    let rates =
        rates_csv(&times).replace(HEADER, "t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps");
    let path = write_text(&dir, "rates_as_inc.csv", &rates);
    let e = ImuReader::open(&path, &static_opts(Layout::Rinscope)).unwrap_err();
    let msg = names_file(&e, &path);
    assert!(matches!(e, LogError::Implausible { .. }));
    assert!(
        msg.contains("look like rates, not increments")
            && msg.contains("dv_x_mps, dv_y_mps, dv_z_mps")
            && msg.contains("200 Hz"),
        "{msg}"
    );
    // Increments (9.81 m/s² × 0.005 s = 0.049 m/s) under rate names.
    let inc = rates_csv(&times).replace("0.01,0.02,9.81\n", "5e-5,1e-4,0.04905\n");
    let path = write_text(&dir, "inc_as_rates.csv", &inc);
    let msg = ImuReader::open(&path, &static_opts(Layout::Rinscope)).unwrap_err().to_string();
    assert!(
        msg.contains("0.0491 m/s²") && msg.contains("9.81 m/s²") && msg.contains("look like increments, not rates"),
        "{msg}"
    );
    assert!(msg.contains("set kind = increments"), "{msg}");
    // PSINS holds increments; a PSINS file of rates says so.
    let mut psins = String::new();
    for t in &times {
        psins += &format!("1e-5 2e-5 3e-5 0.01 0.02 9.81 {t}\n");
    }
    let path = write_text(&dir, "psins_rates.txt", &psins);
    let msg = ImuReader::open(&path, &static_opts(Layout::Psins)).unwrap_err().to_string();
    assert!(msg.contains("look like rates") && msg.contains("Psins layout is fixed to increments"), "{msg}");
    // Degrees per second declared as rad/s: 4.178e-3 deg/s is the Earth rate (7.292e-5 rad/s × 180/π).
    let deg = rates_csv(&times).replace("1e-5,2e-5,3e-5", "0.004178,0,0");
    let path = write_text(&dir, "deg_as_rad.csv", &deg);
    let msg = ImuReader::open(&path, &static_opts(Layout::Rinscope)).unwrap_err().to_string();
    assert!(msg.contains("degrees declared as radians") && msg.contains("gyro_x_rad_per_s"), "{msg}");
    // g declared as m/s².
    let g = rates_csv(&times).replace("0.01,0.02,9.81", "0.001,0.002,1.0003");
    let path = write_text(&dir, "g_as_mps2.csv", &g);
    let msg = ImuReader::open(&path, &static_opts(Layout::Rinscope)).unwrap_err().to_string();
    assert!(msg.contains("units of g declared as m/s²"), "{msg}");
    // A plausible file passes, and the report is available on its own.
    let path = write_text(&dir, "good.csv", &rates_csv(&times));
    assert!(ImuReader::open(&path, &static_opts(Layout::Rinscope)).is_ok());
    let report =
        rinscope::io::check_static(&path, &ImuOptions::new(Layout::Rinscope), &StaticCheck::default()).unwrap();
    assert!(report.problems.is_empty() && (report.dt_s - 0.005).abs() < 1e-12 && report.samples == 300);
}

#[test]
fn mcap_topic_choice() {
    let dir = scratch("mcap_topics");
    let msg = |i: u64| {
        (1_000 + i * 10_000_000, cdr_imu(1, u32::try_from(i).unwrap() * 10_000_000, "imu", [0.0; 3], [0.0, 0.0, 9.8]))
    };
    let a = McapTopic { topic: "/imu_a", schema: "sensor_msgs/msg/Imu", messages: (0..5).map(msg).collect() };
    let b = McapTopic { topic: "/imu_b", schema: "sensor_msgs/msg/Imu", messages: (0..3).map(msg).collect() };
    let path = dir.join("two.mcap");
    write_mcap(&path, &[a, b], true);
    let e = ImuReader::open(&path, &ImuOptions::new(Layout::Ros2)).unwrap_err();
    let text = names_file(&e, &path);
    assert!(
        text.contains("2 sensor_msgs/msg/Imu topics") && text.contains("/imu_b (sensor_msgs/msg/Imu, cdr)"),
        "{text}"
    );
    let mut opts = ImuOptions::new(Layout::Ros2);
    opts.topic = Some("/imu_b".into());
    assert_eq!(samples(ImuReader::open(&path, &opts).unwrap()).len(), 3);
    opts.topic = Some("/nope".into());
    assert!(matches!(ImuReader::open(&path, &opts).unwrap_err(), LogError::Topic { .. }));
}
