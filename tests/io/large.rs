//! Memory stays flat in the file length (ignored by default: it writes ~0.5 GB; run with
//! `cargo test -- --ignored large`).

use crate::common::{cdr_imu, scratch};
use rinscope::io::{Col, ColumnReader, ReadOptions, TableWriter};

/// Peak resident memory of this process so far, from /proc (Linux), in MiB.
fn peak_rss_mib() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let kib: f64 = status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.split_whitespace().next()?.parse().ok())
        .unwrap_or(0.0);
    kib / 1024.0
}

#[test]
#[ignore = "writes ~0.5 GB; run alone: cargo test -- --ignored large"]
fn large_files_stream_in_flat_memory() {
    let dir = scratch("large");
    let rows: u64 = std::env::var("LOGIO_LARGE_ROWS").ok().and_then(|v| v.parse().ok()).unwrap_or(3_000_000);
    let names = [
        "t_s",
        "gyro_x_rad_per_s",
        "gyro_y_rad_per_s",
        "gyro_z_rad_per_s",
        "accel_x_mps2",
        "accel_y_mps2",
        "accel_z_mps2",
    ];
    let before = peak_rss_mib();
    for ext in ["csv", "npy", "parquet"] {
        let path = dir.join(format!("big.{ext}"));
        let mut w = TableWriter::create(&path, &names).unwrap();
        for i in 0..rows {
            let t = i as f64 * 0.005;
            w.write_row(&[t, 1e-5 * t.sin(), 2e-5, 3e-5, 0.01, 0.02, 9.80665 + 1e-3 * t.cos()]).unwrap();
        }
        w.finish().unwrap();
        let size_mib = std::fs::metadata(&path).unwrap().len() as f64 / (1 << 20) as f64;
        let cols: Vec<Col> = (0..7).map(Col::Index).collect();
        let mut r = ColumnReader::open(&path, &cols, &ReadOptions::default()).unwrap();
        let mut row = [0.0; 7];
        let mut n = 0u64;
        while r.next_row(&mut row).unwrap() {
            n += 1;
        }
        assert_eq!(n, rows);
        let peak = peak_rss_mib();
        eprintln!("{ext}: {size_mib:.0} MiB file, {rows} rows; peak RSS {peak:.0} MiB (was {before:.0} MiB before)");
        assert!(peak - before < 128.0, "{ext}: memory grew by {:.0} MiB", peak - before);
        std::fs::remove_file(&path).unwrap();
    }
    // MCAP: messages written one by one with the mcap crate, read back with logio.
    let path = dir.join("big.mcap");
    let mut w = mcap::Writer::new(std::io::BufWriter::new(std::fs::File::create(&path).unwrap())).unwrap();
    let schema = w.add_schema("sensor_msgs/msg/Imu", "ros2msg", b"").unwrap();
    let channel = w.add_channel(schema, "/imu", "cdr", &std::collections::BTreeMap::new()).unwrap();
    for i in 0..rows {
        let ns = 1_700_000_000_000_000_000 + i * 5_000_000;
        let cdr = cdr_imu(
            (ns / 1_000_000_000) as i32,
            (ns % 1_000_000_000) as u32,
            "imu",
            [1e-5, 0.0, 0.0],
            [0.0, 0.0, 9.8 + (i % 7) as f64 * 1e-3],
        );
        let header =
            mcap::records::MessageHeader { channel_id: channel, sequence: i as u32, log_time: ns, publish_time: ns };
        w.write_to_known_channel(&header, &cdr).unwrap();
    }
    w.finish().unwrap();
    drop(w);
    let size_mib = std::fs::metadata(&path).unwrap().len() as f64 / (1 << 20) as f64;
    let cols: Vec<Col> = (0..7).map(Col::Index).collect();
    let mut r = ColumnReader::open(&path, &cols, &ReadOptions::default()).unwrap();
    let mut row = [0.0; 7];
    let mut n = 0u64;
    while r.next_row(&mut row).unwrap() {
        n += 1;
    }
    assert_eq!(n, rows);
    let peak = peak_rss_mib();
    eprintln!("mcap: {size_mib:.0} MiB file, {rows} messages; peak RSS {peak:.0} MiB (was {before:.0} MiB before)");
    assert!(peak - before < 128.0, "mcap: memory grew by {:.0} MiB", peak - before);
}
