//! Every format and layout reads the same synthetic data to the same samples.
//!
//! Golden values: the truth is `common::truth_rates` / `truth_increments` (formulas in the test);
//! each file is written from the truth converted into that file's frame and units, so reading it
//! back must give the truth again.

use crate::common::*;
use rinscope::io::{Frame, ImuOptions, ImuReader, Layout, SampleKind, StartTime, TimeUnit, frame_matrix};

const N: usize = 40;

fn rinscope_rates_rows() -> Vec<Vec<f64>> {
    truth_rates(N).iter().map(|s| vec![s.t_s, s.gyro.x, s.gyro.y, s.gyro.z, s.accel.x, s.accel.y, s.accel.z]).collect()
}

fn csv(header: &str, rows: &[Vec<f64>], sep: &str) -> String {
    let mut text = format!("{header}\n");
    for r in rows {
        text += &r.iter().map(f64::to_string).collect::<Vec<_>>().join(sep);
        text.push('\n');
    }
    text
}

#[test]
fn rinscope_csv_rates_and_increments() {
    let dir = scratch("rinscope_csv");
    let header = "t_s,gyro_x_rad_per_s,gyro_y_rad_per_s,gyro_z_rad_per_s,accel_x_mps2,accel_y_mps2,accel_z_mps2";
    let text = format!(
        "# exported by a test\n# comment lines are allowed at the top\n{}",
        csv(header, &rinscope_rates_rows(), ", ")
    );
    let path = write_text(&dir, "rates.csv", &text);
    let reader = ImuReader::open(&path, &ImuOptions::new(Layout::Rinscope)).unwrap();
    assert_eq!(reader.kind(), SampleKind::Rates);
    assert_same(&samples(reader), &truth_rates(N), 0.0);

    // Increments in degrees / m/s, extra columns ignored, column order shuffled.
    let inc = truth_increments(N);
    let deg = 180.0 / std::f64::consts::PI;
    let mut text = String::from("temp_c_1,dv_z_mps,dv_y_mps,dv_x_mps,t_s,dtheta_x_deg,dtheta_y_deg,dtheta_z_deg\n");
    for s in &inc {
        text += &format!(
            "21.5,{},{},{},{},{},{},{}\n",
            s.accel.z,
            s.accel.y,
            s.accel.x,
            s.t_s,
            s.gyro.x * deg,
            s.gyro.y * deg,
            s.gyro.z * deg
        );
    }
    let path = write_text(&dir, "inc.csv", &text);
    let reader = ImuReader::open(&path, &ImuOptions::new(Layout::Rinscope)).unwrap();
    assert_eq!(reader.kind(), SampleKind::Increments);
    assert_same(&samples(reader), &inc, 1e-18);
}

#[test]
fn parquet_matches_csv() {
    let dir = scratch("parquet_same");
    let names = [
        "t_ns",
        "gyro_x_rad_per_s",
        "gyro_y_rad_per_s",
        "gyro_z_rad_per_s",
        "accel_x_mps2",
        "accel_y_mps2",
        "accel_z_mps2",
    ];
    let rows = rinscope_rates_rows();
    let stamps: Vec<i64> = (0..N as i64).map(|i| T0_NS + i * 10_000_000).collect();
    let path = dir.join("imu.parquet");
    // 7 rows per row group: the reader must cross row-group boundaries.
    write_parquet(&path, &names, &rows, Some(&stamps), 7);
    let reader = ImuReader::open(&path, &ImuOptions::new(Layout::Rinscope)).unwrap();
    assert_eq!(reader.start_time(), Some(StartTime::Nanoseconds(T0_NS)));
    assert_same(&samples(reader), &truth_rates(N), 1e-15);
}

#[test]
fn npy7_matches() {
    let dir = scratch("npy7");
    let inc = truth_increments(N);
    let rows: Vec<Vec<f64>> =
        inc.iter().map(|s| vec![s.t_s, s.gyro.x, s.gyro.y, s.gyro.z, s.accel.x, s.accel.y, s.accel.z]).collect();
    let path = dir.join("imu.npy");
    write_npy(&path, &rows, "<f8");
    let mut opts = ImuOptions::new(Layout::Npy7 { time: TimeUnit::Seconds });
    opts.frame = Some(Frame::Named("rfu".into()));
    assert_same(&samples(ImuReader::open(&path, &opts).unwrap()), &inc, 0.0);
    // float32 arrays widen exactly; compare to f32 precision.
    let path = dir.join("imu32.npy");
    write_npy(&path, &rows, "<f4");
    assert_same(&samples(ImuReader::open(&path, &opts).unwrap()), &inc, 1e-7);
}

#[test]
fn mcap_ros2_imu_matches() {
    let dir = scratch("mcap");
    let flu = frame_matrix("flu").unwrap();
    let truth = truth_rates(N);
    let messages: Vec<(u64, Vec<u8>)> = truth
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let ns = T0_NS + i as i64 * 10_000_000;
            let (w, a) = (in_frame(&flu, &s.gyro), in_frame(&flu, &s.accel));
            let cdr = cdr_imu(
                (ns / 1_000_000_000) as i32,
                (ns % 1_000_000_000) as u32,
                "imu_link",
                [w.x, w.y, w.z],
                [a.x, a.y, a.z],
            );
            (ns as u64 + 5_000, cdr)
        })
        .collect();
    let other =
        McapTopic { topic: "/tf", schema: "tf2_msgs/msg/TFMessage", messages: vec![(T0_NS as u64, vec![0, 1, 0, 0])] };
    let imu = McapTopic { topic: "/imu/data", schema: "sensor_msgs/msg/Imu", messages };
    for summary in [true, false] {
        let path = dir.join(format!("imu_summary_{summary}.mcap"));
        write_mcap(&path, &[other.clone(), imu.clone()], summary);
        let reader = ImuReader::open(&path, &ImuOptions::new(Layout::Ros2)).unwrap();
        assert_eq!(reader.start_time(), Some(StartTime::Nanoseconds(T0_NS)));
        // Its length: the summary's message count of the IMU topic (not /tf's) at 100 Hz; none without.
        let hint = reader.duration_hint_s();
        assert_eq!(hint.map(|d| (d * 100.0).round()), summary.then_some(N as f64), "{hint:?}");
        // FLU → RFU is a permutation with a sign: exact.
        assert_same(&samples(reader), &truth, 0.0);
    }
}

#[test]
fn mcap_zero_stamp_falls_back_to_log_time() {
    let dir = scratch("mcap_logtime");
    let messages =
        (0..12u64).map(|i| (1_000_000_000 + i * 5_000_000, cdr_imu(0, 0, "", [0.0; 3], [0.0, 0.0, 9.8]))).collect();
    let path = dir.join("imu.mcap");
    write_mcap(&path, &[McapTopic { topic: "/imu", schema: "sensor_msgs/msg/Imu", messages }], true);
    let reader = ImuReader::open(&path, &ImuOptions::new(Layout::Ros2)).unwrap();
    let s = samples(reader);
    assert_eq!(s.len(), 12);
    assert!((s[11].t_s - 0.055).abs() < 1e-15);
}

#[test]
fn psins_kfgins_kalibr_layouts() {
    let dir = scratch("named_layouts");
    let inc = truth_increments(N);
    let rates = truth_rates(N);
    // PSINS [wm vm t], RFU; once header-less, once with a header line.
    let psins: Vec<Vec<f64>> = inc
        .iter()
        .map(|s| vec![s.gyro.x, s.gyro.y, s.gyro.z, s.accel.x, s.accel.y, s.accel.z, s.t_s + 100.0])
        .collect();
    for (name, header) in [("psins.txt", None), ("psins_h.csv", Some("wx,wy,wz,vx,vy,vz,t"))] {
        let text = match header {
            Some(h) => csv(h, &psins, ","),
            None => csv("", &psins, " ").trim_start().to_owned(),
        };
        let path = write_text(&dir, name, &text);
        let reader = ImuReader::open(&path, &ImuOptions::new(Layout::Psins)).unwrap();
        assert_eq!(reader.start_time(), Some(StartTime::Seconds(100.0)));
        assert_same(&samples(reader), &inc, 1e-12);
    }
    // KF-GINS: t (GPS SOW), dtheta, dv in FRD, whitespace-separated, no header, an 8th column (odometer).
    let frd = frame_matrix("frd").unwrap();
    let mut text = String::new();
    for s in &inc {
        let (g, a) = (in_frame(&frd, &s.gyro), in_frame(&frd, &s.accel));
        text += &format!("{}\t{} {} {}  {} {} {} 0.0\n", 345_600.0 + s.t_s, g.x, g.y, g.z, a.x, a.y, a.z);
    }
    let path = write_text(&dir, "kfgins.txt", &text);
    let reader = ImuReader::open(&path, &ImuOptions::new(Layout::KfGins)).unwrap();
    assert_same(&samples(reader), &inc, 1e-9);
    // Kalibr imu0.csv with the EuRoC comment header; frame given (here FLU).
    let flu = frame_matrix("flu").unwrap();
    let mut text = String::from(
        "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n",
    );
    for (i, s) in rates.iter().enumerate() {
        let (g, a) = (in_frame(&flu, &s.gyro), in_frame(&flu, &s.accel));
        text += &format!("{},{},{},{},{},{},{}\n", T0_NS + i as i64 * 10_000_000, g.x, g.y, g.z, a.x, a.y, a.z);
    }
    let path = write_text(&dir, "imu0.csv", &text);
    let mut opts = ImuOptions::new(Layout::Kalibr);
    assert!(ImuReader::open(&path, &opts).is_err(), "Kalibr has no standard frame: it must be given");
    opts.frame = Some(Frame::Named("flu".into()));
    let reader = ImuReader::open(&path, &opts).unwrap();
    assert_eq!(reader.columns()[0], "timestamp [ns]");
    assert_same(&samples(reader), &rates, 0.0);
    // The Kalibr wiki's plain header spelling.
    let text = text.replacen(
        "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]",
        "timestamp,omega_x,omega_y,omega_z,alpha_x,alpha_y,alpha_z",
        1,
    );
    let path = write_text(&dir, "imu0_wiki.csv", &text);
    assert_same(&samples(ImuReader::open(&path, &opts).unwrap()), &rates, 0.0);
}

#[test]
fn unit_conversions_from_names() {
    // 1 deg/h = π/648000 rad/s and 1 g = 9.80665 m/s² by definition.
    let dir = scratch("units");
    let text = "t_ms,gyro_x_deg_per_h,gyro_y_deg_per_s,gyro_z_rad_per_s,accel_x_g,accel_y_mg,accel_z_mps2\n0,15,1,0,1,1000,0\n10,15,1,0,1,1000,0\n";
    let path = write_text(&dir, "u.csv", text);
    let s = samples(ImuReader::open(&path, &ImuOptions::new(Layout::Rinscope)).unwrap());
    assert!((s[1].t_s - 0.010).abs() < 1e-18);
    assert!((s[0].gyro.x - 15.0 * std::f64::consts::PI / 648_000.0).abs() < 1e-18);
    assert!((s[0].gyro.y - std::f64::consts::PI / 180.0).abs() < 1e-16);
    assert!((s[0].accel.x - 9.80665).abs() < 1e-15 && (s[0].accel.y - 9.80665).abs() < 1e-12);
}

#[test]
fn each_format_tells_the_log_length_before_it_is_read() {
    // 20 000 rows at 100 Hz: 200 s. `duration_hint_s` is what a replay sizes its plots' buckets by
    // before reading the log: .npy's shape and Parquet's metadata state the rows; a text file's
    // are its data bytes over a row's mean length, of the first rows and of the file's last 64 KiB
    // (f64 `Display` of varying width here, a header and comments before the data: 1.7 % long,
    // accepted within 2 %, i.e. 3000 ± 60 buckets); MCAP's summary counts its messages
    // (`mcap_ros2_imu_matches`); a pipe says nothing.
    const ROWS: usize = 20_000;
    let dir = scratch("length_hint");
    let inc = truth_increments(ROWS);
    let rows: Vec<Vec<f64>> =
        inc.iter().map(|s| vec![s.t_s, s.gyro.x, s.gyro.y, s.gyro.z, s.accel.x, s.accel.y, s.accel.z]).collect();
    let length = ROWS as f64 * 0.01;
    let npy = dir.join("imu.npy");
    write_npy(&npy, &rows, "<f8");
    let mut opts = ImuOptions::new(Layout::Npy7 { time: TimeUnit::Seconds });
    opts.frame = Some(Frame::Named("rfu".into()));
    let hint = ImuReader::open(&npy, &opts).unwrap().duration_hint_s().expect("npy states its rows");
    assert!((hint - length).abs() < 1e-9, "npy: {hint} s");

    let names = ["t_s", "dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad", "dv_x_mps", "dv_y_mps", "dv_z_mps"];
    let parquet = dir.join("imu.parquet");
    write_parquet(&parquet, &names, &rows, None, 4096);
    let hint = ImuReader::open(&parquet, &ImuOptions::new(Layout::Rinscope)).unwrap().duration_hint_s();
    assert!((hint.expect("parquet states its rows") - length).abs() < 1e-9, "parquet: {hint:?} s");

    let text = format!(
        "# a comment line\n# another, longer: the data start after these\n{}",
        csv(&names.join(","), &rows, ",")
    );
    let path = write_text(&dir, "imu.csv", &text);
    let hint = ImuReader::open(&path, &ImuOptions::new(Layout::Rinscope)).unwrap().duration_hint_s().expect("csv");
    assert!((hint / length - 1.0).abs() < 0.02, "csv: {hint} s for {length} s");
}
