//! Streaming table writers (CSV, Parquet, .npy) that only ever replace the target when finished.
//!
//! Rows go to `PATH.partial`, a [`PartialFile`] (locked, never through a symlink; see
//! [`crate::io::files`]). [`TableWriter::finish`] flushes, fsyncs, renames the
//! partial onto `PATH` and fsyncs the directory. On any error, or if the writer is dropped
//! unfinished, the partial is removed and an existing `PATH` is left untouched. A `PATH` that is
//! a symlink or a directory is refused.
//!
//! Columns: `t_s` first, then f64 columns whose names carry their unit (see [`crate::io::imu::units`]),
//! made of ASCII letters, digits and `_`. Memory stays flat: CSV and .npy stream through a
//! buffer, Parquet holds one row group (65 536 rows).
//!
//! * CSV: a header line, then one line per row; each value is the shortest text that parses back
//!   to the same f64 (so a round trip is bit-exact), in exponent form outside 1e-5 ≤ |v| < 1e16.
//! * Parquet: non-nullable float64 columns, snappy, a row group per 65 536 rows.
//! * .npy: `<f8`, C order, shape (rows, columns); the column names are not stored (the format has
//!   no place for them), the caller knows their order.

use crate::io::error::{LogError, Result};
use crate::io::files::PartialFile;
use crate::io::formats::npy::NpyWriter;
use crate::io::formats::parquet_io::ParquetWriter;
use crate::io::formats::sniff::Format;
use crate::io::imu::units::split_unit;
use std::fs::File;
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
    /// The locked `PATH.partial` (see [`crate::io::files`]); `None` once committed.
    out: Option<PartialFile>,
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

/// What a table's columns must be.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Shape {
    /// A time series: `t_s` first, every name with a unit.
    TimeSeries,
    /// Any table (an Allan curve against τ, fitted coefficients): names only checked for their
    /// characters and repeats (coefficient units such as °/√h are not units `io` converts).
    Keyed,
}

fn check_columns(path: &Path, columns: &[&str], shape: Shape) -> Result<()> {
    let bad =
        |column: &str, problem: String| LogError::Unit { file: path.to_path_buf(), column: column.to_owned(), problem };
    if columns.is_empty() || (shape == Shape::TimeSeries && columns.first() != Some(&"t_s")) {
        return Err(LogError::Layout {
            file: path.to_path_buf(),
            problem: format!("the first column must be t_s (got {:?})", columns.first()),
        });
    }
    for (i, c) in columns.iter().enumerate() {
        if c.is_empty() || !c.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_') {
            return Err(bad(c, "a column name is ASCII letters, digits and _".into()));
        }
        if shape == Shape::TimeSeries && split_unit(c).is_none() {
            return Err(bad(
                c,
                "the name carries no unit: end it with _<unit>, e.g. _rad, _deg_per_h, _mps2, _m, _s".into(),
            ));
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
    let _ =
        if v == 0.0 || (1e-5..1e16).contains(&a) || !v.is_finite() { write!(out, "{v}") } else { write!(out, "{v:e}") };
}

impl TableWriter {
    /// Creates a writer for `path` in the format its extension names (`.csv`, `.parquet`, `.npy`).
    ///
    /// # Errors
    /// Unknown extension or an MCAP one, bad column names, `PATH.partial` locked by another writer
    /// (or a symlink), `PATH` a symlink or directory, or the partial cannot be created.
    pub fn create(path: impl AsRef<Path>, columns: &[&str]) -> Result<Self> {
        Self::create_shaped(path.as_ref(), columns, Shape::TimeSeries)
    }

    /// A writer for a table that is not a time series (an Allan curve against `tau_s`, one row of
    /// fitted coefficients per axis): any first column; names of ASCII letters, digits and `_`,
    /// each once (they need not end in a unit `io` knows).
    ///
    /// # Errors
    /// As [`Self::create`].
    pub fn create_keyed(path: impl AsRef<Path>, columns: &[&str]) -> Result<Self> {
        Self::create_shaped(path.as_ref(), columns, Shape::Keyed)
    }

    fn create_shaped(path: &Path, columns: &[&str], shape: Shape) -> Result<Self> {
        let format = Format::from_extension(path);
        let output = |problem: String| LogError::Output { file: path.to_path_buf(), problem };
        let format = match format {
            Some(f @ (Format::Text | Format::Parquet | Format::Npy)) => f,
            _ => {
                return Err(output("the extension must be .csv, .parquet or .npy".into()));
            }
        };
        check_columns(path, columns, shape)?;
        if std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink()) {
            return Err(output("the output path is a symlink; refusing to write through it".into()));
        }
        let out = PartialFile::create(path).map_err(|e| output(e.to_string()))?;
        let file = out.file().try_clone().map_err(|e| LogError::io(out.partial(), "cannot open", e))?;
        let names: Vec<String> = columns.iter().map(|c| (*c).to_owned()).collect();
        let mut this = Self {
            path: path.to_path_buf(),
            out: Some(out),
            columns: names,
            backend: None,
            rows: 0,
            line: String::new(),
        };
        let backend = match format {
            Format::Parquet => {
                ParquetWriter::new(&this.path, file, &this.columns).map(|w| Backend::Parquet(Box::new(w)))
            }
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

    /// The file it becomes when finished.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
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
            None => Err(LogError::Output { file: self.path.clone(), problem: "the writer failed earlier".into() }),
            Some(Backend::Csv(out)) => {
                self.line.clear();
                for (i, &v) in row.iter().enumerate() {
                    if i > 0 {
                        self.line.push(',');
                    }
                    push_f64(&mut self.line, v);
                }
                self.line.push('\n');
                out.write_all(self.line.as_bytes()).map_err(|e| LogError::io(&self.path, "cannot write", e))
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
                return Err(LogError::Output { file: self.path.clone(), problem: "the writer failed earlier".into() });
            }
            Some(Backend::Csv(mut out)) => {
                out.flush().map_err(io)?;
                out.into_inner().map_err(|e| io(e.into_error()))?
            }
            Some(Backend::Parquet(w)) => w.finish(&self.path)?,
            Some(Backend::Npy(w)) => w.finish(&self.path)?,
        };
        drop(file);
        let out = self
            .out
            .take()
            .ok_or_else(|| LogError::Output { file: self.path.clone(), problem: "already finished".into() })?;
        out.commit().map_err(|e| LogError::Output { file: self.path.clone(), problem: e.to_string() })?;
        Ok(self.rows)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shortest_text_round_trips() {
        for v in [0.0, -0.0, 1.0, 0.1, 1e-7, 123456.789, 1e300, -2.5e-310, f64::MAX, f64::MIN_POSITIVE, 1.0 / 3.0] {
            let mut s = String::new();
            push_f64(&mut s, v);
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{s}");
        }
        let mut s = String::new();
        push_f64(&mut s, 1e300);
        assert_eq!(s, "1e300");
    }
}
