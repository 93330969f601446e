//! Time conversions (GPS week rollover, nanosecond precision) and frame conversions.

use crate::common::*;
use nalgebra::{Matrix3, Vector3};
use rinscope::io::{Frame, ImuOptions, ImuReader, Layout, StartTime, frame_matrix};

#[test]
fn gps_week_rollover() {
    // KF-GINS stamps in GPS seconds of week crossing the end of a week: 604799.98, 604799.99,
    // then 0.00, 0.01 of the next week. Golden: the week has 604800 s (IS-GPS-200), so the
    // relative times are 0, 0.01, 0.02, 0.03 s.
    let dir = scratch("gps_rollover");
    let text = "604799.98 0 0 0 0 0 0.098\n604799.99 0 0 0 0 0 0.098\n0.00 0 0 0 0 0 0.098\n0.01 0 0 0 0 0 0.098\n";
    let path = write_text(&dir, "week.txt", text);
    let reader = ImuReader::open(&path, &ImuOptions::new(Layout::KfGins)).unwrap();
    let t: Vec<f64> = samples(reader).iter().map(|s| s.t_s).collect();
    for (got, want) in t.iter().zip([0.0, 0.01, 0.02, 0.03]) {
        assert!((got - want).abs() < 1e-9, "{t:?}");
    }
    // A small backward step is not a rollover: it is an error.
    let path = write_text(&dir, "back.txt", "100.00 0 0 0 0 0 0\n100.01 0 0 0 0 0 0\n99.5 0 0 0 0 0 0\n");
    let mut reader = ImuReader::open(&path, &ImuOptions::new(Layout::KfGins)).unwrap();
    assert!(reader.nth(2).unwrap().is_err());
}

#[test]
fn nanosecond_stamps_keep_1_ns_resolution() {
    // Stamps 1.403715273262142976e18 ns + {0, 1, 2, 1_000_000_001} ns. As f64 the absolute stamps
    // are 256 ns apart at best (2^60 < 1.4e18 < 2^61: ulp = 2^8 ns); relative to the first they are exact.
    let dir = scratch("ns_precision");
    let mut text = String::from(
        "t_ns,gyro_x_rad_per_s,gyro_y_rad_per_s,gyro_z_rad_per_s,accel_x_mps2,accel_y_mps2,accel_z_mps2\n",
    );
    let offsets = [0i64, 1, 2, 1_000_000_001];
    for o in offsets {
        text += &format!("{},0,0,0,0,0,9.8\n", T0_NS + o);
    }
    let path = write_text(&dir, "ns.csv", &text);
    let mut opts = ImuOptions::new(Layout::Rinscope);
    opts.nominal_dt_s = Some(1.0); // the 1 s step is no gap here
    let reader = ImuReader::open(&path, &opts).unwrap();
    let s = samples(reader);
    assert_eq!(s[1].t_s, 1e-9);
    assert_eq!(s[2].t_s, 2e-9);
    assert_eq!(s[3].t_s, 1.000_000_001);
    assert!((T0_NS as f64 + 1.0) - T0_NS as f64 == 0.0, "f64 alone would lose the nanosecond");
    // The same through Parquet int64 and the Kalibr layout.
    let pq = dir.join("ns.parquet");
    let names = [
        "t_ns",
        "gyro_x_rad_per_s",
        "gyro_y_rad_per_s",
        "gyro_z_rad_per_s",
        "accel_x_mps2",
        "accel_y_mps2",
        "accel_z_mps2",
    ];
    let rows: Vec<Vec<f64>> = offsets.iter().map(|_| vec![0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 9.8]).collect();
    let stamps: Vec<i64> = offsets.iter().map(|o| T0_NS + o).collect();
    write_parquet(&pq, &names, &rows, Some(&stamps), 100);
    let reader = ImuReader::open(&pq, &opts).unwrap();
    assert_eq!(reader.start_time(), Some(StartTime::Nanoseconds(T0_NS)));
    assert_eq!(samples(reader)[1].t_s, 1e-9);
    let kalibr = write_text(&dir, "imu0.csv", &text.replacen("t_ns,gyro", "timestamp,gyro", 1));
    opts.layout = Layout::Kalibr;
    opts.frame = Some(Frame::Named("rfu".into()));
    assert_eq!(samples(ImuReader::open(&kalibr, &opts).unwrap())[2].t_s, 2e-9);
}

#[test]
fn frame_conversions() {
    let frd = frame_matrix("frd").unwrap();
    // A rotation about the forward axis is x in FRD and +y in RFU; FRD's down is RFU's −z.
    assert_eq!(frd * Vector3::x(), Vector3::y());
    assert_eq!(frd * Vector3::y(), Vector3::x());
    assert_eq!(frd * Vector3::z(), -Vector3::z());
    let flu = frame_matrix("flu").unwrap();
    // FLU: forward → +y, left → −x, up → +z.
    assert_eq!(flu * Vector3::new(1.0, 2.0, 3.0), Vector3::new(-2.0, 1.0, 3.0));
    assert_eq!(frame_matrix("rfu").unwrap(), Matrix3::identity());
    assert_eq!(frame_matrix("ENU").unwrap(), Matrix3::identity());
    assert_eq!(frame_matrix("ned").unwrap(), frd);
    assert_eq!(frame_matrix("nwu").unwrap(), flu);
    // A level IMU at rest in FRD reads specific force −g on z (up is −z): +g on RFU z.
    assert_eq!(frd * Vector3::new(0.0, 0.0, -9.8), Vector3::new(0.0, 0.0, 9.8));
    // An explicit matrix: a 30° yaw mounting, accepted as a rotation and applied as given.
    let (s, c) = 30f64.to_radians().sin_cos();
    let yaw = Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
    assert_eq!(Frame::Matrix(yaw).to_rfu().unwrap(), yaw);
    assert!(Frame::Matrix(yaw * 1.01).to_rfu().is_err());

    // Through a file: a KF-GINS (FRD) increment about forward becomes +y.
    let dir = scratch("frame_file");
    let path = write_text(&dir, "f.txt", "0.00 1e-4 0 0 0 0 -0.098\n0.01 1e-4 0 0 0 0 -0.098\n");
    let s = samples(ImuReader::open(&path, &ImuOptions::new(Layout::KfGins)).unwrap());
    assert_eq!(s[0].gyro, Vector3::new(0.0, 1e-4, 0.0));
    assert_eq!(s[0].accel, Vector3::new(0.0, 0.0, 0.098));
    let mut opts = ImuOptions::new(Layout::KfGins);
    opts.frame = Some(Frame::Named("fru".into()));
    let e = ImuReader::open(&path, &opts).unwrap_err().to_string();
    assert!(e.starts_with(&path.display().to_string()) && e.contains("left-handed"), "{e}");
}
