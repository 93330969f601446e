//! Streaming table writers (CSV, Parquet, .npy) that only ever replace the target when finished.
//!
//! Rows go to `PATH.partial`, created with `create_new` (so an existing file, or a symlink, in
//! that place is refused and never followed). [`TableWriter::finish`] flushes, fsyncs, renames the
//! partial onto `PATH` and fsyncs the directory. On any error, or if the writer is dropped
//! unfinished, the partial is removed and an existing `PATH` is left untouched. A `PATH` that is
//! a symlink or a directory is refused.
//!
//! Columns: `t_s` first, then f64 columns whose names carry their unit (see [`crate::io::units`]),
//! made of ASCII letters, digits and `_`. Memory stays flat: CSV and .npy stream through a
//! buffer, Parquet holds one row group (65 536 rows).
//!
//! * CSV: a header line, then one line per row; each value is the shortest text that parses back
//!   to the same f64 (so a round trip is bit-exact), in exponent form outside 1e-5 ≤ |v| < 1e16.
//! * Parquet: non-nullable float64 columns, snappy, a row group per 65 536 rows.
//! * .npy: `<f8`, C order, shape (rows, columns); the column names are not stored (the format has
//!   no place for them), the caller knows their order.

use crate::io::error::{LogError, Result};
use crate::io::npy::NpyWriter;
use crate::io::parquet_io::ParquetWriter;
use crate::io::sniff::Format;
use crate::io::units::split_unit;
use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

enum Backend {
    Csv(BufWriter<File>),
    Parquet(Box<ParquetWriter>),
    Npy(NpyWriter),
}

/// Writes a table row by row; see the module docs. Drop it unfinished to abandon the file.
pub struct TableWriter {
    path: PathBuf,
    partial: PathBuf,
    columns: Vec<String>,
    backend: Option<Backend>,
    rows: u64,
    line: String,
}

impl std::fmt::Debug for TableWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TableWriter")
            .field("path", &self.path)
            .field("columns", &self.columns)
            .field("rows", &self.rows)
            .finish_non_exhaustive()
    }
}

/// `PATH.partial`.
fn partial_path(path: &Path) -> PathBuf {
    let mut name = path
        .file_name()
        .map(std::ffi::OsStr::to_os_string)
        .unwrap_or_default();
    name.push(".partial");
    path.with_file_name(name)
}

fn check_columns(path: &Path, columns: &[&str]) -> Result<()> {
    let bad = |column: &str, problem: String| LogError::Unit {
        file: path.to_path_buf(),
        column: column.to_owned(),
        problem,
    };
    if columns.first() != Some(&"t_s") {
        return Err(LogError::Layout {
            file: path.to_path_buf(),
            problem: format!("the first column must be t_s (got {:?})", columns.first()),
        });
    }
    for (i, c) in columns.iter().enumerate() {
        if c.is_empty() || !c.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_') {
            return Err(bad(
                c,
                "a column name is ASCII letters, digits and _".into(),
            ));
        }
        if split_unit(c).is_none() {
            return Err(bad(c, "the name carries no unit: end it with _<unit>, e.g. _rad, _deg_per_h, _mps2, _m, _s".into()));
        }
        if columns.get(..i).is_some_and(|before| before.contains(c)) {
            return Err(bad(c, "the column appears twice".into()));
        }
    }
    Ok(())
}

/// Shortest round-trip text of an f64.
fn push_f64(out: &mut String, v: f64) {
    use std::fmt::Write as _;
    let a = v.abs();
    let _ = if v == 0.0 || (1e-5..1e16).contains(&a) || !v.is_finite() {
        write!(out, "{v}")
    } else {
        write!(out, "{v:e}")
    };
}

impl TableWriter {
    /// Creates a writer for `path` in the format its extension names (`.csv`, `.parquet`, `.npy`).
    ///
    /// # Errors
    /// Unknown extension or an MCAP one, bad column names, `PATH.partial` already present (or a
    /// symlink), `PATH` a symlink or directory, or the partial cannot be created.
    pub fn create(path: impl AsRef<Path>, columns: &[&str]) -> Result<Self> {
        let path = path.as_ref();
        let format = Format::from_extension(path);
        let output = |problem: String| LogError::Output {
            file: path.to_path_buf(),
            problem,
        };
        let format = match format {
            Some(f @ (Format::Text | Format::Parquet | Format::Npy)) => f,
            _ => {
                return Err(output(
                    "the extension must be .csv, .parquet or .npy".into(),
                ));
            }
        };
        check_columns(path, columns)?;
        if let Ok(meta) = std::fs::symlink_metadata(path) {
            if meta.file_type().is_symlink() {
                return Err(output(
                    "the output path is a symlink; refusing to write through it".into(),
                ));
            }
            if meta.is_dir() {
                return Err(output("the output path is a directory".into()));
            }
        }
        let partial = partial_path(path);
        if let Ok(meta) = std::fs::symlink_metadata(&partial) {
            let what = if meta.file_type().is_symlink() {
                "a symlink"
            } else {
                "a file"
            };
            return Err(output(format!(
                "{} is {what} in the way (another export running, or one that crashed?); remove it to write",
                partial.display()
            )));
        }
        let file = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&partial)
            .map_err(|e| LogError::io(&partial, "cannot create", e))?;
        let names: Vec<String> = columns.iter().map(|c| (*c).to_owned()).collect();
        let mut this = Self {
            path: path.to_path_buf(),
            partial,
            columns: names,
            backend: None,
            rows: 0,
            line: String::new(),
        };
        let backend = match format {
            Format::Parquet => ParquetWriter::new(&this.path, file, &this.columns)
                .map(|w| Backend::Parquet(Box::new(w))),
            Format::Npy => NpyWriter::new(&this.path, file, columns.len()).map(Backend::Npy),
            _ => {
                let mut out = BufWriter::with_capacity(1 << 16, file);
                let header = format!("{}\n", columns.join(","));
                out.write_all(header.as_bytes())
                    .map(|()| Backend::Csv(out))
                    .map_err(|e| LogError::io(path, "cannot write", e))
            }
        };
        // On error `this` is dropped here, which removes the partial.
        this.backend = Some(backend?);
        Ok(this)
    }

    /// The columns.
    #[must_use]
    pub fn columns(&self) -> &[String] {
        &self.columns
    }

    /// Appends a row (one value per column).
    ///
    /// # Errors
    /// A row of the wrong length, or a write error; the writer is then unusable (drop it, which
    /// removes the partial).
    pub fn write_row(&mut self, row: &[f64]) -> Result<()> {
        if row.len() != self.columns.len() {
            self.backend = None;
            return Err(LogError::Shape {
                file: self.path.clone(),
                shape: format!("row of {}", row.len()),
                expected: format!("{} values, one per column", self.columns.len()),
            });
        }
        let result = match &mut self.backend {
            None => Err(LogError::Output {
                file: self.path.clone(),
                problem: "the writer failed earlier".into(),
            }),
            Some(Backend::Csv(out)) => {
                self.line.clear();
                for (i, &v) in row.iter().enumerate() {
                    if i > 0 {
                        self.line.push(',');
                    }
                    push_f64(&mut self.line, v);
                }
                self.line.push('\n');
                out.write_all(self.line.as_bytes())
                    .map_err(|e| LogError::io(&self.path, "cannot write", e))
            }
            Some(Backend::Parquet(w)) => w.write_row(&self.path, row),
            Some(Backend::Npy(w)) => w.write_row(&self.path, row),
        };
        match result {
            Ok(()) => {
                self.rows += 1;
                Ok(())
            }
            Err(e) => {
                self.backend = None;
                Err(e)
            }
        }
    }

    /// Finishes the file: flush, fsync, rename `PATH.partial` onto `PATH`, fsync the directory.
    /// Returns the number of rows.
    ///
    /// # Errors
    /// Any write, sync or rename error; the partial is then removed and `PATH` left as it was.
    pub fn finish(mut self) -> Result<u64> {
        let io = |e| LogError::io(&self.path, "cannot write", e);
        let file = match self.backend.take() {
            None => {
                return Err(LogError::Output {
                    file: self.path.clone(),
                    problem: "the writer failed earlier".into(),
                });
            }
            Some(Backend::Csv(mut out)) => {
                out.flush().map_err(io)?;
                out.into_inner().map_err(|e| io(e.into_error()))?
            }
            Some(Backend::Parquet(w)) => w.finish(&self.path)?,
            Some(Backend::Npy(w)) => w.finish(&self.path)?,
        };
        file.sync_all()
            .map_err(|e| LogError::io(&self.path, "cannot sync", e))?;
        drop(file);
        std::fs::rename(&self.partial, &self.path)
            .map_err(|e| LogError::io(&self.path, "cannot rename the partial onto", e))?;
        // The partial is gone; nothing to clean up any more.
        self.partial = PathBuf::new();
        let dir = match self.path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        if let Ok(d) = File::open(dir) {
            d.sync_all()
                .map_err(|e| LogError::io(dir, "cannot sync", e))?;
        }
        Ok(self.rows)
    }
}

impl Drop for TableWriter {
    fn drop(&mut self) {
        if !self.partial.as_os_str().is_empty() {
            self.backend = None;
            let _ = std::fs::remove_file(&self.partial);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shortest_text_round_trips() {
        for v in [
            0.0,
            -0.0,
            1.0,
            0.1,
            1e-7,
            123456.789,
            1e300,
            -2.5e-310,
            f64::MAX,
            f64::MIN_POSITIVE,
            1.0 / 3.0,
        ] {
            let mut s = String::new();
            push_f64(&mut s, v);
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{s}");
        }
        let mut s = String::new();
        push_f64(&mut s, 1e300);
        assert_eq!(s, "1e300");
    }

    #[test]
    fn partial_name() {
        assert_eq!(
            partial_path(Path::new("/a/b.csv")),
            Path::new("/a/b.csv.partial")
        );
    }
}
