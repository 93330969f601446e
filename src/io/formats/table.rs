//! The streaming column reader: open a file, name the columns wanted, get rows of f64 one at a time.

use crate::io::error::{Location, LogError, Result};
use crate::io::formats::psins_imu::PsinsHeader;
use crate::io::formats::sniff::{Format, detect_format};
use std::fmt;
use std::path::{Path, PathBuf};

/// A column: by header name (CSV, Parquet, MCAP) or by 0-based index (any format; the only way for .npy).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Col {
    /// Exact header name.
    Name(String),
    /// 0-based position.
    Index(usize),
}

impl From<&str> for Col {
    fn from(name: &str) -> Self {
        Self::Name(name.to_owned())
    }
}

impl From<usize> for Col {
    fn from(index: usize) -> Self {
        Self::Index(index)
    }
}

impl fmt::Display for Col {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Name(n) => write!(f, "{n:?}"),
            Self::Index(i) => write!(f, "index {i}"),
        }
    }
}

/// Whether a text file has a header line (see the rules in the `text` module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HeaderMode {
    /// A first line with a non-numeric field is the header; or a `#` comment line just before
    /// all-numeric data, if it has as many fields.
    #[default]
    Auto,
    /// The first table line (or the `#` line before numeric data) is the header, even if numeric.
    Present,
    /// No header: every line is data.
    Absent,
}

/// Options for [`ColumnReader::open`].
#[derive(Debug, Clone, Default)]
pub struct ReadOptions {
    /// Text files: header detection.
    pub header: HeaderMode,
    /// MCAP: the topic to read; `None` takes the file's only `sensor_msgs/msg/Imu` topic.
    pub topic: Option<String>,
    /// Accept NaN and ±inf cells (default: they are an error naming row and column).
    pub allow_non_finite: bool,
}

/// What a format backend provides.
pub(crate) trait Source {
    /// Every column of the file, in file order.
    fn all_columns(&self) -> &[String];
    /// Restricts reading to these columns (indices into `all_columns`), in this order.
    fn select(&mut self, indices: &[usize]) -> Result<()>;
    /// Fills `out` (and `exact`, the exact integer when the cell is one) with the selected columns
    /// of the next row; `false` at the end.
    fn next_row(&mut self, out: &mut [f64], exact: &mut [Option<i64>]) -> Result<bool>;
    /// The last row returned (or being read when an error occurred).
    fn location(&self) -> Location;
    /// Appends up to `max_rows` rows of the selected columns to `out` (row-major); returns how many.
    /// Sources without exact integers (.npy) override this to decode a block at once; the default
    /// reads row by row.
    fn next_rows(&mut self, out: &mut Vec<f64>, max_rows: usize) -> Result<usize> {
        let width = self.selected_width();
        let mut row = vec![0.0; width];
        let mut exact = vec![None; width];
        let mut n = 0;
        while n < max_rows && self.next_row(&mut row, &mut exact)? {
            out.extend_from_slice(&row);
            n += 1;
        }
        Ok(n)
    }
    /// The number of selected columns.
    fn selected_width(&self) -> usize;
    /// True when no cell carries an exact integer ([`ColumnReader::exact_integer`] is always None).
    fn never_exact(&self) -> bool {
        false
    }
    /// A PSINS SIMU file's header.
    fn psins_header(&self) -> Option<&PsinsHeader> {
        None
    }
    /// The data rows the whole file holds: exact where the format states it (.npy's shape,
    /// Parquet's metadata, an MCAP summary's message count), estimated from the bytes read so far
    /// for text; None where unknown (an MCAP file without a summary).
    fn rows_hint(&self) -> Option<u64> {
        None
    }
}

/// Reads selected columns of a table as f64 rows, streaming: memory does not grow with the file.
///
/// ```no_run
/// use rinscope::io::{Col, ColumnReader, ReadOptions};
/// let mut reader = ColumnReader::open("imu.csv", &[Col::from("t_s"), Col::from("gyro_x_rad_per_s")], &ReadOptions::default())?;
/// let mut row = [0.0; 2];
/// while reader.next_row(&mut row)? {
///     println!("{} {}", row[0], row[1]);
/// }
/// # Ok::<(), rinscope::io::LogError>(())
/// ```
pub struct ColumnReader {
    path: PathBuf,
    format: Format,
    source: Box<dyn Source + Send>,
    names: Vec<String>,
    exact: Vec<Option<i64>>,
    allow_non_finite: bool,
    /// A decoder panicked: the source's state is unknown, it is not read again.
    poisoned: bool,
}

/// Runs a call into a format decoder, turning a panic inside it into [`LogError::Corrupt`].
///
/// This module's own code does not panic, but the Parquet and MCAP libraries have asserts that corrupt
/// files can reach (found by the garbage tests); this is the backstop. (With `panic = "abort"`
/// the process still aborts; the default hook still prints the panic message.)
fn guarded<T>(path: &Path, format: Format, f: impl FnOnce() -> Result<T>) -> Result<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|payload| {
        let what = payload
            .downcast_ref::<&str>()
            .map(|s| (*s).to_owned())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        Err(LogError::corrupt(
            path,
            format!("the {format:?} decoder gave up on this file (a corrupt file; internal panic: {what})"),
        ))
    })
}

impl fmt::Debug for ColumnReader {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("ColumnReader")
            .field("path", &self.path)
            .field("format", &self.format)
            .field("columns", &self.names)
            .finish_non_exhaustive()
    }
}

impl ColumnReader {
    /// Opens `path` (format from the extension, checked against the content) and selects `columns`.
    /// An empty `columns` opens the file only to look at [`Self::all_columns`].
    ///
    /// For MCAP the columns are fixed: `t_ns, gyro_x_rad_per_s, gyro_y_rad_per_s, gyro_z_rad_per_s,
    /// accel_x_mps2, accel_y_mps2, accel_z_mps2` (see the `mcap_imu` module); for a PSINS SIMU file
    /// they are `imufile.m`'s `[wm vm t]`: `dtheta_{x,y,z}_rad, dv_{x,y,z}_mps, t_s` (absolute).
    ///
    /// # Errors
    /// Unreadable file, content not of the extension's format, a malformed header, or a missing
    /// column (the error lists the columns that exist).
    pub fn open(path: impl AsRef<Path>, columns: &[Col], options: &ReadOptions) -> Result<Self> {
        let path = path.as_ref();
        let format = detect_format(path)?;
        let mut source: Box<dyn Source + Send> = guarded(path, format, || {
            Ok(match format {
                Format::Text => Box::new(crate::io::formats::text::TextSource::open(path, options.header)?)
                    as Box<dyn Source + Send>,
                Format::Npy => Box::new(crate::io::formats::npy::NpySource::open(path)?),
                Format::Parquet => Box::new(crate::io::formats::parquet_io::ParquetSource::open(path)?),
                Format::PsinsImu => Box::new(crate::io::formats::psins_imu::PsinsSource::open(path)?),
                Format::Mcap => {
                    Box::new(crate::io::formats::mcap_imu::McapImuSource::open(path, options.topic.as_deref())?)
                }
            })
        })?;
        let all = source.all_columns();
        let mut indices = Vec::with_capacity(columns.len());
        for col in columns {
            let index = match col {
                Col::Name(name) => all.iter().position(|n| n == name),
                Col::Index(i) => (*i < all.len()).then_some(*i),
            };
            let Some(index) = index else {
                return Err(LogError::MissingColumn {
                    file: path.to_path_buf(),
                    column: col.to_string(),
                    available: all.iter().enumerate().map(|(i, n)| format!("{n:?} (index {i})")).collect(),
                });
            };
            indices.push(index);
        }
        let names = indices.iter().filter_map(|&i| all.get(i).cloned()).collect();
        guarded(path, format, || source.select(&indices))?;
        Ok(Self {
            path: path.to_path_buf(),
            format,
            source,
            names,
            exact: vec![None; columns.len()],
            allow_non_finite: options.allow_non_finite,
            poisoned: false,
        })
    }

    /// The file.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The file's format.
    #[must_use]
    pub fn format(&self) -> Format {
        self.format
    }

    /// Every column of the file (header names; `index N` where the format has none).
    #[must_use]
    pub fn all_columns(&self) -> &[String] {
        self.source.all_columns()
    }

    /// The selected columns' names, in selection order.
    #[must_use]
    pub fn columns(&self) -> &[String] {
        &self.names
    }

    /// Where the last row came from (1-based data row, and file line for text).
    #[must_use]
    pub fn location(&self) -> Location {
        self.source.location()
    }

    /// Reads the next row into `row` (one value per selected column). `Ok(false)` at the end.
    ///
    /// # Errors
    /// A cell that is not a number, NaN/inf (unless allowed), a short or truncated row, a read error.
    ///
    /// # Panics
    /// Never; a `row` of the wrong length is an error.
    pub fn next_row(&mut self, row: &mut [f64]) -> Result<bool> {
        if row.len() != self.names.len() {
            return Err(LogError::Shape {
                file: self.path.clone(),
                shape: format!("row buffer of {}", row.len()),
                expected: format!("one value per selected column ({})", self.names.len()),
            });
        }
        if self.poisoned {
            return Err(LogError::corrupt(&self.path, "the decoder failed earlier on this file"));
        }
        let (source, exact) = (&mut self.source, &mut self.exact);
        let more = guarded(&self.path, self.format, || source.next_row(row, exact));
        if matches!(&more, Err(LogError::Corrupt { detail, .. }) if detail.contains("internal panic")) {
            self.poisoned = true;
        }
        if !more? {
            return Ok(false);
        }
        if !self.allow_non_finite
            && let Some(k) = row.iter().position(|v| !v.is_finite())
        {
            return Err(LogError::NonFinite {
                file: self.path.clone(),
                at: self.source.location(),
                column: self.names.get(k).cloned().unwrap_or_default(),
                value: row.get(k).map_or_else(String::new, f64::to_string),
            });
        }
        Ok(true)
    }

    /// The exact integer value of selected column `k` in the last row, when the source holds one:
    /// an integer literal in text, an integer Parquet column, the MCAP stamp. Use it for
    /// nanosecond time stamps, which an f64 cannot hold (`1.7e18` has a 256 ns resolution).
    #[must_use]
    pub fn exact_integer(&self, k: usize) -> Option<i64> {
        self.exact.get(k).copied().flatten()
    }

    /// Appends up to `max_rows` rows to `out` (row-major, one value per selected column) and
    /// returns how many; 0 at the end.
    ///
    /// # Errors
    /// As [`Self::next_row`]; rows read before the error stay in `out`.
    pub fn next_batch(&mut self, out: &mut Vec<f64>, max_rows: usize) -> Result<usize> {
        if self.poisoned {
            return Err(LogError::corrupt(&self.path, "the decoder failed earlier on this file"));
        }
        let start = out.len();
        let source = &mut self.source;
        let n = guarded(&self.path, self.format, || source.next_rows(out, max_rows));
        if matches!(&n, Err(LogError::Corrupt { detail, .. }) if detail.contains("internal panic")) {
            self.poisoned = true;
        }
        let n = n?;
        let width = self.names.len().max(1);
        if !self.allow_non_finite
            && let Some(i) = first_non_finite(&out[start..])
        {
            let row_in_batch = i / width;
            let end = self.source.location();
            return Err(LogError::NonFinite {
                file: self.path.clone(),
                at: Location { row: end.row - (n - 1 - row_in_batch) as u64, line: None },
                column: self.names.get(i % width).cloned().unwrap_or_default(),
                value: out[start + i].to_string(),
            });
        }
        Ok(n)
    }

    /// The data rows the whole file holds: exact for .npy, Parquet and an MCAP file with a summary,
    /// estimated for text (a recording's plots size their buckets by it); None where unknown.
    #[must_use]
    pub fn rows_hint(&self) -> Option<u64> {
        self.source.rows_hint()
    }

    /// The header of a PSINS SIMU file ([`Format::PsinsImu`]); `None` for other formats.
    #[must_use]
    pub fn psins_header(&self) -> Option<&PsinsHeader> {
        self.source.psins_header()
    }

    /// True when the format never carries exact integers (rows can be read in blocks).
    #[must_use]
    pub fn reads_in_blocks(&self) -> bool {
        self.source.never_exact()
    }
}

/// The index of the first value that is not finite. Blocks of 16 values are checked without an
/// early exit first (`all_finite`; an element-wise search with one was ~10 instructions per value,
/// a tenth of a replay's log reader), then the block that has one is searched.
fn first_non_finite(values: &[f64]) -> Option<usize> {
    const BLOCK: usize = 16;
    for (b, block) in values.chunks(BLOCK).enumerate() {
        if !crate::math::stats::all_finite(block) {
            return block.iter().position(|v| !v.is_finite()).map(|i| b * BLOCK + i);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::first_non_finite;

    #[test]
    fn the_first_non_finite_value_is_found_in_every_block_and_position() {
        // Against the element-wise search, for lengths around the block's 16 and every position of
        // a NaN, an infinity or two of them.
        for len in 0..50 {
            let clean: Vec<f64> = (0..len).map(|i| i as f64 * 0.5 - 3.0).collect();
            assert_eq!(first_non_finite(&clean), None, "len {len}");
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                for at in 0..len {
                    let mut v = clean.clone();
                    v[at] = bad;
                    if at + 17 < len {
                        v[at + 17] = f64::NAN;
                    }
                    assert_eq!(first_non_finite(&v), Some(at), "len {len}, {bad} at {at}");
                }
            }
        }
    }
}
