//! Output files are written to `PATH.partial` and renamed onto `PATH` only when complete.

use std::path::{Path, PathBuf};

/// The partial-file name used while writing `path`.
#[must_use]
pub fn partial_path(path: &Path) -> PathBuf {
    let mut name = path.file_name().map(|n| n.to_os_string()).unwrap_or_default();
    name.push(".partial");
    path.with_file_name(name)
}

/// Writes `bytes` to `path` through its partial file and a rename: never a half-written file.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = partial_path(path);
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_partial_file_sits_beside_the_final_one() {
        assert_eq!(partial_path(Path::new("out/x.rrd")), PathBuf::from("out/x.rrd.partial"));
        assert_eq!(partial_path(Path::new("x.json")), PathBuf::from("x.json.partial"));
    }
}
