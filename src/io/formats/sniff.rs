//! File formats, from the extension and from the first bytes ("is this .npy really NumPy?").

use crate::io::error::{LogError, Result};
use std::io::Read;
use std::path::Path;

/// NumPy `.npy` magic: `\x93NUMPY`.
pub(crate) const NPY_MAGIC: &[u8] = b"\x93NUMPY";
/// Parquet magic, at the start and at the end of the file.
pub(crate) const PARQUET_MAGIC: &[u8] = b"PAR1";
/// MCAP magic: `\x89MCAP0\r\n`.
pub(crate) const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// A table format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Delimited text: comma-separated with a header, or whitespace/comma-separated without
    /// (`.csv`, `.txt`, `.tsv`, `.dat`, `.imu`, `.log`).
    Text,
    /// A PSINS SIMU file as PSINS's `imufile.m` writes it: text (usually `.imu`, any text
    /// extension) told from other text by its first line, a `%` comment naming PSINS and SIMU.
    /// Read as the columns `imufile.m` returns, `dtheta_{x,y,z}_rad, dv_{x,y,z}_mps, t_s`.
    PsinsImu,
    /// NumPy `.npy` (v1, v2, v3), 2-D, float64 or float32.
    Npy,
    /// Apache Parquet (`.parquet`, `.pq`).
    Parquet,
    /// MCAP (`.mcap`) with ROS 2 `sensor_msgs/msg/Imu` messages in CDR.
    Mcap,
}

impl Format {
    /// The format an extension promises, if any (case-insensitive).
    #[must_use]
    pub fn from_extension(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "csv" | "txt" | "tsv" | "dat" | "imu" | "log" => Self::Text,
            "npy" => Self::Npy,
            "parquet" | "pq" => Self::Parquet,
            "mcap" => Self::Mcap,
            _ => return None,
        })
    }

    pub(crate) fn describe(self) -> &'static str {
        match self {
            Self::Text => "a text table (.csv/.txt)",
            Self::PsinsImu => "a PSINS SIMU file (imufile.m)",
            Self::Npy => "a NumPy .npy file",
            Self::Parquet => "a Parquet file",
            Self::Mcap => "an MCAP file",
        }
    }
}

/// What the first bytes of a file look like.
fn classify(head: &[u8]) -> (Option<Format>, String) {
    if head.starts_with(NPY_MAGIC) {
        return (Some(Format::Npy), "its content starts with the NumPy magic \\x93NUMPY".into());
    }
    if head.starts_with(PARQUET_MAGIC) {
        return (Some(Format::Parquet), "its content starts with the Parquet magic PAR1".into());
    }
    if head.starts_with(MCAP_MAGIC) {
        return (Some(Format::Mcap), "its content starts with the MCAP magic \\x89MCAP0\\r\\n".into());
    }
    if head.is_empty() {
        return (None, "it is empty".into());
    }
    let text_like = !head.contains(&0)
        && match std::str::from_utf8(head) {
            Ok(_) => true,
            // A multi-byte character cut by the end of the sniffed block is still text.
            Err(e) => e.error_len().is_none(),
        };
    if text_like {
        let line = head.split(|&b| b == b'\n').next().unwrap_or(head);
        let first_line: String = String::from_utf8_lossy(line).trim_end_matches('\r').chars().take(60).collect();
        if crate::io::formats::psins_imu::names_psins_simu(line) {
            return (
                Some(Format::PsinsImu),
                format!("its first line {first_line:?} is a PSINS SIMU file's (imufile.m)"),
            );
        }
        return (Some(Format::Text), format!("its content is text (first line {first_line:?})"));
    }
    let hex: Vec<String> = head.iter().take(8).map(|b| format!("{b:02x}")).collect();
    (None, format!("its content is binary of no known format (first bytes {})", hex.join(" ")))
}

/// The format of `path`: from its extension, checked against its first bytes.
///
/// A file without a known extension is classified by content alone. A text file whose first line
/// is a `%` comment naming PSINS and SIMU is [`Format::PsinsImu`], whatever its text extension.
///
/// # Errors
/// [`LogError::Io`] if the file cannot be read, [`LogError::NotTheFormat`] if the content does not
/// match the extension (a CSV named `.npy`, a truncated Parquet without its `PAR1` footer, ...).
pub fn detect_format(path: &Path) -> Result<Format> {
    let mut file = crate::io::files::open_input(path).map_err(|e| LogError::io(path, "cannot open", e))?;
    let mut head = Vec::with_capacity(512);
    (&mut file).take(512).read_to_end(&mut head).map_err(|e| LogError::io(path, "cannot read", e))?;
    let (found, description) = classify(&head);
    let expected = Format::from_extension(path);
    let not_the_format = |expected: &str, found: String| LogError::NotTheFormat {
        file: path.to_path_buf(),
        expected: expected.to_owned(),
        found,
    };
    match (expected, found) {
        (Some(e), Some(f)) if e == f => {}
        // A PSINS SIMU file is text: its first line tells it from other text.
        (Some(Format::Text), Some(Format::PsinsImu)) => return Ok(Format::PsinsImu),
        (Some(e), _) => return Err(not_the_format(e.describe(), description)),
        (None, Some(_)) => {}
        (None, None) => return Err(not_the_format("a log (unknown extension)", description)),
    }
    let format = expected.or(found).unwrap_or(Format::Text);
    if format == Format::Parquet {
        check_parquet_footer(path, &mut file)?;
    }
    Ok(format)
}

fn check_parquet_footer(path: &Path, file: &mut std::fs::File) -> Result<()> {
    use std::io::{Seek, SeekFrom};
    let len = file.metadata().map_err(|e| LogError::io(path, "cannot read", e))?.len();
    let mut tail = [0u8; 4];
    let ok = len >= 12
        && file.seek(SeekFrom::End(-4)).is_ok()
        && file.read_exact(&mut tail).is_ok()
        && tail == PARQUET_MAGIC;
    if ok {
        Ok(())
    } else {
        Err(LogError::corrupt(
            path,
            format!(
                "Parquet file of {len} bytes does not end with the PAR1 footer magic: the file is truncated (was it still being written?)"
            ),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classifies() {
        assert_eq!(classify(b"\x93NUMPY\x01\x00").0, Some(Format::Npy));
        assert_eq!(classify(b"PAR1....").0, Some(Format::Parquet));
        assert_eq!(classify(b"\x89MCAP0\r\n").0, Some(Format::Mcap));
        assert_eq!(classify(b"t_s,gyro_x_rad_per_s\n0,1\n").0, Some(Format::Text));
        assert_eq!(classify(b"\x00\x01\x02\xff").0, None);
        assert_eq!(classify(b"").0, None);
        // "é" (c3 a9) cut after its first byte is still text.
        assert_eq!(classify(b"t_s,caf\xc3").0, Some(Format::Text));
        // imufile.m's first line; PSINS and SIMU on a later line do not count.
        assert_eq!(
            classify(b"% PSINS-format SIMU log file. (DO NOT MODIFY!)\r\n% 2024-01-01\n").0,
            Some(Format::PsinsImu)
        );
        assert_eq!(classify(b"% a log\n% PSINS-format SIMU log file.\n").0, Some(Format::Text));
    }
}
