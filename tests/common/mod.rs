//! What the tests that run the built binary share: the command, a scratch folder, its output.
#![allow(dead_code)] // each test crate uses its own part

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The binary under test; `RINSCOPE_TEST_BIN=PATH` runs another build instead (e.g. a copy from
/// before a fix, to show a test fails without it). No test may open a window, whatever the machine
/// has.
pub fn rinscope() -> Command {
    let bin = std::env::var_os("RINSCOPE_TEST_BIN").unwrap_or_else(|| env!("CARGO_BIN_EXE_rinscope").into());
    let mut c = Command::new(bin);
    c.env_remove("DISPLAY").env_remove("WAYLAND_DISPLAY");
    c
}

/// An empty folder of this test's own (the test crate, the process and `name` in its name).
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rinscope-{}-{}-{name}", env!("CARGO_CRATE_NAME"), std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// A CSV table (`--export-format csv`): its header and rows of numbers.
pub fn csv_table(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header = lines.next().expect("header").split(',').map(String::from).collect();
    let rows = lines.map(|l| l.split(',').map(|v| v.parse::<f64>().expect("number")).collect()).collect();
    (header, rows)
}

/// A CDR (little-endian) `sensor_msgs/msg/Imu`, fields in order, each aligned to its size.
fn cdr_imu(ns: i64, w: [f64; 3], a: [f64; 3]) -> Vec<u8> {
    let (sec, nanosec) = (ns.div_euclid(1_000_000_000) as i32, ns.rem_euclid(1_000_000_000) as u32);
    let mut b = vec![0u8, 1, 0, 0];
    b.extend(sec.to_le_bytes());
    b.extend(nanosec.to_le_bytes());
    b.extend(4u32.to_le_bytes());
    b.extend(b"imu\0");
    let mut f64s = |values: &[f64]| {
        for v in values {
            while !(b.len() - 4).is_multiple_of(8) {
                b.push(0);
            }
            b.extend(v.to_le_bytes());
        }
    };
    f64s(&[0.0, 0.0, 0.0, 1.0]);
    f64s(&[0.0; 9]);
    f64s(&w);
    f64s(&[0.0; 9]);
    f64s(&a);
    f64s(&[0.0; 9]);
    b
}

/// Writes rows of [t_ns, ω x y z, f x y z] as an MCAP of `sensor_msgs/msg/Imu` on `/imu` with the
/// `mcap` crate's writer (chunks of `chunk_bytes`, or its default; a summary with statistics).
pub fn write_imu_mcap(path: &Path, rows: &[Vec<f64>], chunk_bytes: Option<u64>) {
    use std::io::Write as _;
    let file = std::io::BufWriter::new(std::fs::File::create(path).expect("mcap"));
    let mut options = mcap::WriteOptions::new();
    if let Some(n) = chunk_bytes {
        options = options.chunk_size(Some(n));
    }
    let mut w = options.create(file).expect("mcap writer");
    let schema = w.add_schema("sensor_msgs/msg/Imu", "ros2msg", b"std_msgs/Header header\n").expect("schema");
    let channel = w.add_channel(schema, "/imu", "cdr", &std::collections::BTreeMap::new()).expect("channel");
    for (k, r) in rows.iter().enumerate() {
        let ns = r[0] as i64;
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence: k as u32,
            log_time: ns.max(0) as u64,
            publish_time: ns.max(0) as u64,
        };
        w.write_to_known_channel(&header, &cdr_imu(ns, [r[1], r[2], r[3]], [r[4], r[5], r[6]])).expect("message");
    }
    w.finish().expect("finish");
    w.into_inner().flush().expect("flush");
}
