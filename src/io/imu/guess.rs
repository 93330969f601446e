//! Which layout a file is in, from its extension and its first lines, where that is unambiguous;
//! where it is not, the error lists the candidates and the key that chooses (`imu.layout`,
//! `--imu-layout`).

use crate::io::error::{LogError, Result};
use crate::io::formats::sniff::Format;
use std::io::Read;
use std::path::Path;

/// The most of a file read to guess its layout.
const HEAD_BYTES: u64 = 16 * 1024;

/// The layout name (as `imu.layout` spells it) of the IMU file at `path`.
///
/// # Errors
/// The file cannot be read, or its content fits several layouts (the message lists them).
pub fn guess_layout(path: &Path) -> Result<&'static str> {
    match Format::from_extension(path) {
        Some(Format::Npy) => return Ok("npy7"),
        Some(Format::Mcap) => return Ok("ros2"),
        Some(Format::Parquet) => return Ok("rinscope"),
        _ => {}
    }
    if crate::io::formats::sniff::detect_format(path)? == Format::PsinsImu {
        return Ok("psins-imu");
    }
    let head = read_head(path)?;
    let lines: Vec<&str> = head.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
    let data: Vec<&str> = lines.iter().copied().filter(|l| !l.starts_with('%') && !l.starts_with("//")).collect();
    let Some(first) = data.first() else {
        return Err(layout_error(path, "it has no data lines to tell its layout from".into()));
    };
    let fields = |l: &str| -> Vec<f64> {
        l.split(|c: char| c == ',' || c.is_whitespace())
            .filter(|f| !f.is_empty())
            .filter_map(|f| f.parse().ok())
            .collect()
    };
    let lower = first.to_ascii_lowercase();
    if lower.starts_with("#timestamp") || lower.starts_with("timestamp") {
        return Ok("kalibr");
    }
    if lower.starts_with('#')
        || fields(first).len() < first.split(|c: char| c == ',' || c.is_whitespace()).filter(|f| !f.is_empty()).count()
    {
        // A header of names: rinscope's own units-in-names layout (its reader lists what it lacks).
        return Ok("rinscope");
    }
    let rows: Vec<Vec<f64>> = data.iter().take(12).map(|l| fields(l)).collect();
    let n = rows[0].len();
    if n < 7 {
        return Err(layout_error(
            path,
            format!(
                "its first data line has {n} numbers; the headerless layouts have 7: [wm vm t] (psins), [t dθ dv] (kf-gins, npy7), [t_ns ω α] (kalibr)"
            ),
        ));
    }
    let increasing =
        |k: usize| rows.len() > 2 && rows.windows(2).all(|w| w[0].len() > k && w[1].len() > k && w[1][k] > w[0][k]);
    let (time_first, time_last) = (increasing(0), increasing(6));
    match (time_first, time_last) {
        (true, false) if rows[0][0] > 1e15 => Ok("kalibr"),
        (true, false) => Ok("kf-gins"),
        (false, true) => Ok("psins"),
        _ => Err(layout_error(
            path,
            "neither its first nor its last column is a clock that increases (or both are): it could be psins ([wm vm t], time last), kf-gins (GPS seconds of week, Δθ, Δv) or kalibr (ns, ω, α)".into(),
        )),
    }
}

fn layout_error(path: &Path, why: String) -> LogError {
    LogError::Layout {
        file: path.to_path_buf(),
        problem: format!(
            "cannot tell the layout: {why}; set imu.layout (--imu-layout) to one of rinscope, psins, psins-imu, kf-gins, kalibr, npy7, ros2"
        ),
    }
}

fn read_head(path: &Path) -> Result<String> {
    let file = crate::io::files::open_input(path).map_err(|e| LogError::io(path, "cannot open", e))?;
    let mut buf = Vec::new();
    file.take(HEAD_BYTES).read_to_end(&mut buf).map_err(|e| LogError::io(path, "cannot read", e))?;
    // The last line may be cut by the byte limit: drop it unless the file ended.
    if buf.len() as u64 == HEAD_BYTES
        && let Some(end) = buf.iter().rposition(|b| *b == b'\n')
    {
        buf.truncate(end);
    }
    Ok(String::from_utf8_lossy(&buf).into_owned())
}
