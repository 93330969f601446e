//! Test helpers: scratch directories, synthetic IMU data and independent writers of each format.

use arrow_array::{ArrayRef, Float64Array, Int64Array, RecordBatch};
use arrow_schema::{DataType, Field, Schema};
use nalgebra::{Matrix3, Vector3};
use rinscope::io::{ImuEvent, ImuReader, ImuSample};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A fresh, empty directory under cargo's per-target temp dir.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("logio-tests").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Sampling interval of the synthetic data: 100 Hz.
pub const DT: f64 = 0.01;
/// First stamp of the synthetic data: 2014-06-25 EuRoC-like nanoseconds (1.4e18 ns).
pub const T0_NS: i64 = 1_403_715_273_262_142_976;

/// The synthetic truth: `n` rate samples in RFU at 100 Hz. The values are arbitrary smooth
/// functions chosen by this test (gravity ~9.81 on z so the static check passes; rates small).
pub fn truth_rates(n: usize) -> Vec<ImuSample> {
    (0..n)
        .map(|i| {
            let t = i as f64 * DT;
            ImuSample {
                t_s: t,
                gyro: Vector3::new(1e-5 * (t * 3.0).sin(), -2e-5 + 1e-6 * i as f64, 4e-5 * (t * 2.0).cos()),
                accel: Vector3::new(0.01 * (t * 5.0).sin(), -0.02, 9.80665 + 1e-3 * (t * 7.0).cos()),
            }
        })
        .collect()
}

/// The same truth as increments over the previous sample (rate × dt; exact enough for a test).
pub fn truth_increments(n: usize) -> Vec<ImuSample> {
    truth_rates(n).into_iter().map(|s| ImuSample { t_s: s.t_s, gyro: s.gyro * DT, accel: s.accel * DT }).collect()
}

/// `v` expressed in a frame whose matrix to RFU is `c` (`v_rfu = c · v_frame`).
pub fn in_frame(c: &Matrix3<f64>, v: &Vector3<f64>) -> Vector3<f64> {
    c.transpose() * v
}

/// Every sample of a reader; panics on any error or gap.
pub fn samples(reader: ImuReader) -> Vec<ImuSample> {
    reader
        .map(|e| match e.unwrap() {
            ImuEvent::Sample(s) => s,
            gap => panic!("unexpected {gap:?}"),
        })
        .collect()
}

/// Asserts two sample lists agree to `tol` (absolute, per component and time).
pub fn assert_same(got: &[ImuSample], want: &[ImuSample], tol: f64) {
    assert_eq!(got.len(), want.len(), "sample count");
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        assert!((g.t_s - w.t_s).abs() <= tol.max(1e-12), "sample {i}: t {} vs {}", g.t_s, w.t_s);
        assert!((g.gyro - w.gyro).abs().max() <= tol, "sample {i}: gyro {:?} vs {:?}", g.gyro, w.gyro);
        assert!((g.accel - w.accel).abs().max() <= tol, "sample {i}: accel {:?} vs {:?}", g.accel, w.accel);
    }
}

/// Writes `text` to `dir/name` and returns the path.
pub fn write_text(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// A .npy v1.0 `<f8` C-order file, encoded here by hand from the format spec (independent of logio's writer).
pub fn write_npy(path: &Path, rows: &[Vec<f64>], descr: &str) {
    let cols = rows.first().map_or(0, Vec::len);
    let dict = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': ({}, {cols}), }}", rows.len());
    let total = (10 + dict.len() + 1).div_ceil(64) * 64;
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend(u16::try_from(total - 10).unwrap().to_le_bytes());
    bytes.extend(dict.as_bytes());
    bytes.resize(total - 1, b' ');
    bytes.push(b'\n');
    for row in rows {
        for v in row {
            match descr {
                "<f4" => bytes.extend((*v as f32).to_le_bytes()),
                _ => bytes.extend(v.to_le_bytes()),
            }
        }
    }
    std::fs::write(path, bytes).unwrap();
}

/// A Parquet file written with the parquet crate's own ArrowWriter (independent of logio's).
/// `int_first` makes column 0 an Int64 column.
pub fn write_parquet(path: &Path, names: &[&str], rows: &[Vec<f64>], int_first: Option<&[i64]>, rows_per_group: usize) {
    let fields: Vec<Field> = names
        .iter()
        .enumerate()
        .map(|(i, n)| {
            Field::new(*n, if i == 0 && int_first.is_some() { DataType::Int64 } else { DataType::Float64 }, false)
        })
        .collect();
    let schema = Arc::new(Schema::new(fields));
    let props = parquet::file::properties::WriterProperties::builder()
        .set_max_row_group_row_count(Some(rows_per_group))
        .build();
    let file = std::fs::File::create(path).unwrap();
    let mut w = parquet::arrow::ArrowWriter::try_new(file, schema.clone(), Some(props)).unwrap();
    let arrays: Vec<ArrayRef> = (0..names.len())
        .map(|c| match (c, int_first) {
            (0, Some(ints)) => Arc::new(Int64Array::from(ints.to_vec())) as ArrayRef,
            _ => Arc::new(Float64Array::from(rows.iter().map(|r| r[c]).collect::<Vec<_>>())) as ArrayRef,
        })
        .collect();
    w.write(&RecordBatch::try_new(schema, arrays).unwrap()).unwrap();
    w.close().unwrap();
}

/// A CDR (little-endian, encapsulation `00 01 00 00`) `sensor_msgs/msg/Imu`, encoded by hand:
/// fields in order, each aligned to its size counted from the end of the 4-byte header.
pub fn cdr_imu(sec: i32, nanosec: u32, frame_id: &str, w: [f64; 3], a: [f64; 3]) -> Vec<u8> {
    let mut b = vec![0u8, 1, 0, 0];
    let align = |b: &mut Vec<u8>, n: usize| {
        while !(b.len() - 4).is_multiple_of(n) {
            b.push(0);
        }
    };
    b.extend(sec.to_le_bytes());
    b.extend(nanosec.to_le_bytes());
    b.extend(u32::try_from(frame_id.len() + 1).unwrap().to_le_bytes());
    b.extend(frame_id.as_bytes());
    b.push(0);
    let f64s = |b: &mut Vec<u8>, values: &[f64]| {
        for v in values {
            align(b, 8);
            b.extend(v.to_le_bytes());
        }
    };
    f64s(&mut b, &[0.0, 0.0, 0.0, 1.0]); // orientation x y z w
    f64s(&mut b, &[0.0; 9]);
    f64s(&mut b, &w);
    f64s(&mut b, &[0.0; 9]);
    f64s(&mut b, &a);
    f64s(&mut b, &[0.0; 9]);
    b
}

/// The ROS 2 message definition text stored as the schema (content is informational for readers).
pub const IMU_MSG_DEF: &str = "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance\n";

/// One MCAP channel's messages: topic, schema name, and (log_time_ns, cdr bytes).
#[derive(Clone)]
pub struct McapTopic<'a> {
    pub topic: &'a str,
    pub schema: &'a str,
    pub messages: Vec<(u64, Vec<u8>)>,
}

/// Writes an MCAP file with the mcap crate's writer (chunked, zstd, with summary by default).
pub fn write_mcap(path: &Path, topics: &[McapTopic<'_>], summary: bool) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let opts = mcap::WriteOptions::new().emit_summary_records(summary).emit_summary_offsets(summary);
    let mut w = opts.create(file).unwrap();
    let mut seq = 0;
    for t in topics {
        let schema_id = w.add_schema(t.schema, "ros2msg", IMU_MSG_DEF.as_bytes()).unwrap();
        let channel = w.add_channel(schema_id, t.topic, "cdr", &BTreeMap::new()).unwrap();
        for (log_time, data) in &t.messages {
            seq += 1;
            let header = mcap::records::MessageHeader {
                channel_id: channel,
                sequence: seq,
                log_time: *log_time,
                publish_time: *log_time,
            };
            w.write_to_known_channel(&header, data).unwrap();
        }
    }
    w.finish().unwrap();
    w.into_inner().flush().unwrap();
}

/// The 1000-point NBS14 set (NIST SP 1065 §12.2): n_0 = 1234567890,
/// n_{i+1} = 16807·n_i mod (2³¹ − 1), y_i = n_i/(2³¹ − 1).
#[allow(dead_code)] // tests/allan_series.rs and tests/figures.rs use it, not the io tests
pub fn nbs14_1000() -> Vec<f64> {
    let mut n = 1_234_567_890u64;
    (0..1000)
        .map(|_| {
            let y = n as f64 / 2_147_483_647.0;
            n = 16_807 * n % 2_147_483_647;
            y
        })
        .collect()
}
