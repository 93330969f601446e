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
