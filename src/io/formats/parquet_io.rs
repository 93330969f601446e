//! Parquet: a column reader that goes row group by row group, and a writer of f64 tables.
//!
//! Reading: the top-level columns are named by the schema; the selected ones are projected (other
//! columns are never decoded) and read one row group at a time in batches of 8192 rows, so memory
//! is bounded by a row group's selected column chunks, never by the file. Column types read:
//! float64, float32 (widened exactly), int64, int32, uint32 (their exact integers are kept, see
//! [`crate::io::ColumnReader::exact_integer`]) and timestamps (as integer nanoseconds). Nulls are errors.
//!
//! The arrow schema is derived from the Parquet schema, not from the embedded `ARROW:schema`
//! (decoding that flatbuffer panics on some corrupt files in arrow-ipc 58).
//!
//! Writing: non-nullable float64 columns, snappy-compressed, one row group per 65 536 rows.

use crate::io::error::{Location, LogError, Result};
use crate::io::formats::table::Source;
use arrow_array::cast::AsArray;
use arrow_array::types::{
    Float32Type, Float64Type, Int32Type, Int64Type, TimestampMicrosecondType, TimestampMillisecondType,
    TimestampNanosecondType, TimestampSecondType, UInt32Type,
};
use arrow_array::{Array, ArrayRef, Float64Array, RecordBatch};
use arrow_schema::{DataType, Field, Schema, SchemaRef, TimeUnit};
use parquet::arrow::ArrowWriter;
use parquet::arrow::ProjectionMask;
use parquet::arrow::arrow_reader::{
    ArrowReaderMetadata, ArrowReaderOptions, ParquetRecordBatchReader, ParquetRecordBatchReaderBuilder,
};
use parquet::basic::Compression;
use parquet::file::properties::WriterProperties;
use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Rows per written row group.
pub(crate) const ROW_GROUP_ROWS: usize = 65_536;
const BATCH_ROWS: usize = 8192;

/// How a selected column's cells become (f64, exact integer).
#[derive(Debug, Clone, Copy)]
enum Kind {
    Float,
    Integer,
    /// Timestamp: multiply by this to get nanoseconds.
    Timestamp(i64),
}

fn kind_of(data_type: &DataType) -> Option<Kind> {
    Some(match data_type {
        DataType::Float64 | DataType::Float32 => Kind::Float,
        DataType::Int64 | DataType::Int32 | DataType::UInt32 => Kind::Integer,
        DataType::Timestamp(unit, _) => Kind::Timestamp(match unit {
            TimeUnit::Second => 1_000_000_000,
            TimeUnit::Millisecond => 1_000_000,
            TimeUnit::Microsecond => 1_000,
            TimeUnit::Nanosecond => 1,
        }),
        _ => return None,
    })
}

/// One cell of a batch column: `None` for null.
fn cell(array: &ArrayRef, kind: Kind, i: usize) -> Option<(f64, Option<i64>)> {
    if array.is_null(i) {
        return None;
    }
    let int = |v: i64| (v as f64, Some(v));
    Some(match (kind, array.data_type()) {
        (_, DataType::Float64) => (array.as_primitive::<Float64Type>().value(i), None),
        (_, DataType::Float32) => (f64::from(array.as_primitive::<Float32Type>().value(i)), None),
        (_, DataType::Int64) => int(array.as_primitive::<Int64Type>().value(i)),
        (_, DataType::Int32) => int(i64::from(array.as_primitive::<Int32Type>().value(i))),
        (_, DataType::UInt32) => int(i64::from(array.as_primitive::<UInt32Type>().value(i))),
        (Kind::Timestamp(scale), DataType::Timestamp(unit, _)) => {
            let raw = match unit {
                TimeUnit::Second => array.as_primitive::<TimestampSecondType>().value(i),
                TimeUnit::Millisecond => array.as_primitive::<TimestampMillisecondType>().value(i),
                TimeUnit::Microsecond => array.as_primitive::<TimestampMicrosecondType>().value(i),
                TimeUnit::Nanosecond => array.as_primitive::<TimestampNanosecondType>().value(i),
            };
            match raw.checked_mul(scale) {
                Some(ns) => int(ns),
                None => (f64::INFINITY, None),
            }
        }
        _ => (f64::NAN, None),
    })
}

/// Checks that every column chunk lies inside the file (parquet asserts on negative offsets).
fn check_chunk_ranges(path: &Path, metadata: &ArrowReaderMetadata, file_len: u64) -> Result<()> {
    for (g, group) in metadata.metadata().row_groups().iter().enumerate() {
        for column in group.columns() {
            let start = column.dictionary_page_offset().unwrap_or_else(|| column.data_page_offset());
            let len = column.compressed_size();
            let inside = u64::try_from(start)
                .ok()
                .zip(u64::try_from(len).ok())
                .and_then(|(s, l)| s.checked_add(l))
                .is_some_and(|end| end <= file_len);
            if !inside {
                return Err(LogError::corrupt(
                    path,
                    format!(
                        "Parquet metadata is corrupt: row group {g}, column {}: chunk at offset {start}, {len} bytes, outside the {file_len}-byte file",
                        column.column_path()
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Checks that the column chunks, page indexes and bloom filters the footer refers to fill the
/// file up to the footer: bytes that nothing refers to are not this table's — two files joined
/// (`cat a.parquet b.parquet`: b's footer then reads a's bytes at b's offsets), or damage.
fn check_unreferenced(path: &Path, metadata: &ArrowReaderMetadata, file: &File, file_len: u64) -> Result<()> {
    use std::io::{Read, Seek, SeekFrom};
    let mut tail = [0u8; 8];
    let mut f = file.try_clone().map_err(|e| LogError::io(path, "cannot read", e))?;
    f.seek(SeekFrom::End(-8))
        .and_then(|_| f.read_exact(&mut tail))
        .map_err(|e| LogError::io(path, "cannot read", e))?;
    let footer_len = u64::from(u32::from_le_bytes([tail[0], tail[1], tail[2], tail[3]]));
    let Some(footer_start) = file_len.checked_sub(8 + footer_len) else {
        return Err(LogError::corrupt(path, "Parquet footer longer than the file"));
    };
    let end = |offset: Option<i64>, len: Option<i64>| -> u64 {
        match (offset, len) {
            (Some(o), Some(l)) => u64::try_from(o).unwrap_or(0).saturating_add(u64::try_from(l).unwrap_or(0)),
            _ => 0,
        }
    };
    let mut data_end = 4; // the leading magic
    for group in metadata.metadata().row_groups() {
        for column in group.columns() {
            let start = column.dictionary_page_offset().unwrap_or_else(|| column.data_page_offset());
            data_end = data_end.max(end(Some(start), Some(column.compressed_size())));
            data_end = data_end.max(end(column.column_index_offset(), column.column_index_length().map(i64::from)));
            data_end = data_end.max(end(column.offset_index_offset(), column.offset_index_length().map(i64::from)));
            data_end = data_end.max(end(column.bloom_filter_offset(), column.bloom_filter_length().map(i64::from)));
        }
    }
    if data_end < footer_start {
        return Err(LogError::corrupt(
            path,
            format!(
                "bytes {data_end}..{footer_start} lie between the table's data and its footer and nothing refers to them: two Parquet files joined into one (the footer of the second reads the first's bytes), or a damaged file"
            ),
        ));
    }
    Ok(())
}

pub(crate) struct ParquetSource {
    path: PathBuf,
    file: File,
    metadata: ArrowReaderMetadata,
    names: Vec<String>,
    /// (selected field index, kind, position in the projected batch)
    selected: Vec<(usize, Kind, usize)>,
    mask: Option<ProjectionMask>,
    next_group: usize,
    reader: Option<ParquetRecordBatchReader>,
    batch: Option<RecordBatch>,
    batch_row: usize,
    row: u64,
}

impl ParquetSource {
    pub(crate) fn open(path: &Path) -> Result<Self> {
        let file = crate::io::files::open_input(path).map_err(|e| LogError::io(path, "cannot open", e))?;
        let metadata = ArrowReaderMetadata::load(&file, ArrowReaderOptions::new().with_skip_arrow_metadata(true))
            .map_err(|e| LogError::corrupt(path, format!("not a readable Parquet file: {e}")))?;
        let file_len = file.metadata().map_err(|e| LogError::io(path, "cannot read", e))?.len();
        check_chunk_ranges(path, &metadata, file_len)?;
        check_unreferenced(path, &metadata, &file, file_len)?;
        let names = metadata.schema().fields().iter().map(|f| f.name().clone()).collect();
        Ok(Self {
            path: path.to_path_buf(),
            file,
            metadata,
            names,
            selected: Vec::new(),
            mask: None,
            next_group: 0,
            reader: None,
            batch: None,
            batch_row: 0,
            row: 0,
        })
    }

    fn parquet_error(&self, e: impl std::fmt::Display) -> LogError {
        LogError::corrupt(&self.path, format!("Parquet read error near data row {}: {e}", self.row + 1))
    }

    /// Makes sure a batch with an unread row is loaded; `false` at the end of the file.
    fn fill(&mut self) -> Result<bool> {
        loop {
            if let Some(batch) = &self.batch {
                if self.batch_row < batch.num_rows() {
                    return Ok(true);
                }
                self.batch = None;
            }
            if let Some(reader) = &mut self.reader {
                match reader.next() {
                    Some(Ok(batch)) => {
                        if batch.num_columns() < self.selected.iter().map(|s| s.2 + 1).max().unwrap_or(0) {
                            return Err(self.parquet_error("a batch is missing projected columns"));
                        }
                        self.batch = Some(batch);
                        self.batch_row = 0;
                        continue;
                    }
                    Some(Err(e)) => return Err(self.parquet_error(e)),
                    None => self.reader = None,
                }
            }
            if self.next_group >= self.metadata.metadata().num_row_groups() {
                return Ok(false);
            }
            let group = self.next_group;
            self.next_group += 1;
            let file = self.file.try_clone().map_err(|e| LogError::io(&self.path, "cannot read", e))?;
            let mut builder = ParquetRecordBatchReaderBuilder::new_with_metadata(file, self.metadata.clone())
                .with_row_groups(vec![group])
                .with_batch_size(BATCH_ROWS);
            if let Some(mask) = &self.mask {
                builder = builder.with_projection(mask.clone());
            }
            self.reader = Some(builder.build().map_err(|e| self.parquet_error(e))?);
        }
    }
}

impl Source for ParquetSource {
    fn all_columns(&self) -> &[String] {
        &self.names
    }

    fn select(&mut self, indices: &[usize]) -> Result<()> {
        let schema = self.metadata.schema().clone();
        let mut roots: Vec<usize> = indices.to_vec();
        roots.sort_unstable();
        roots.dedup();
        self.selected.clear();
        for &i in indices {
            let field = schema.field(i);
            let kind = kind_of(field.data_type()).ok_or_else(|| LogError::ColumnType {
                file: self.path.clone(),
                column: field.name().clone(),
                found: field.data_type().to_string(),
            })?;
            let position = roots.iter().position(|&r| r == i).unwrap_or(0);
            self.selected.push((i, kind, position));
        }
        self.mask = Some(ProjectionMask::roots(self.metadata.parquet_schema(), roots));
        Ok(())
    }

    fn next_row(&mut self, out: &mut [f64], exact: &mut [Option<i64>]) -> Result<bool> {
        if !self.fill()? {
            return Ok(false);
        }
        self.row += 1;
        let Some(batch) = &self.batch else {
            return Ok(false);
        };
        let i = self.batch_row;
        for (k, &(field, kind, position)) in self.selected.iter().enumerate() {
            let array = batch.column(position);
            let Some((value, integer)) = cell(array, kind, i) else {
                return Err(LogError::NonFinite {
                    file: self.path.clone(),
                    at: Location { row: self.row, line: None },
                    column: self.names.get(field).cloned().unwrap_or_default(),
                    value: "null".into(),
                });
            };
            if let (Some(o), Some(e)) = (out.get_mut(k), exact.get_mut(k)) {
                *o = value;
                *e = integer;
            }
        }
        self.batch_row += 1;
        Ok(true)
    }

    fn selected_width(&self) -> usize {
        self.selected.len()
    }

    fn location(&self) -> Location {
        Location { row: self.row, line: None }
    }

    fn rows_hint(&self) -> Option<u64> {
        u64::try_from(self.metadata.metadata().file_metadata().num_rows()).ok()
    }
}

/// Streams rows of f64 into a Parquet file, one row group per [`ROW_GROUP_ROWS`] rows.
pub(crate) struct ParquetWriter {
    writer: ArrowWriter<File>,
    schema: SchemaRef,
    columns: Vec<Vec<f64>>,
}

impl ParquetWriter {
    pub(crate) fn new(path: &Path, file: File, names: &[String]) -> Result<Self> {
        let schema: SchemaRef =
            Arc::new(Schema::new(names.iter().map(|n| Field::new(n, DataType::Float64, false)).collect::<Vec<_>>()));
        let props = WriterProperties::builder()
            .set_compression(Compression::SNAPPY)
            .set_max_row_group_row_count(Some(ROW_GROUP_ROWS))
            .set_created_by(format!("rinscope {}", env!("CARGO_PKG_VERSION")))
            .build();
        let writer = ArrowWriter::try_new(file, schema.clone(), Some(props)).map_err(|e| LogError::Output {
            file: path.to_path_buf(),
            problem: format!("cannot start Parquet: {e}"),
        })?;
        Ok(Self { writer, schema, columns: names.iter().map(|_| Vec::with_capacity(ROW_GROUP_ROWS)).collect() })
    }

    pub(crate) fn write_row(&mut self, path: &Path, row: &[f64]) -> Result<()> {
        for (column, &v) in self.columns.iter_mut().zip(row) {
            column.push(v);
        }
        if self.columns.first().is_some_and(|c| c.len() >= ROW_GROUP_ROWS) {
            self.flush_group(path)?;
        }
        Ok(())
    }

    fn flush_group(&mut self, path: &Path) -> Result<()> {
        if self.columns.first().is_none_or(Vec::is_empty) {
            return Ok(());
        }
        let arrays: Vec<ArrayRef> = self
            .columns
            .iter_mut()
            .map(|c| Arc::new(Float64Array::from(std::mem::replace(c, Vec::with_capacity(ROW_GROUP_ROWS)))) as ArrayRef)
            .collect();
        let fail = |e: parquet::errors::ParquetError| LogError::Output {
            file: path.to_path_buf(),
            problem: format!("Parquet write failed: {e}"),
        };
        let batch = RecordBatch::try_new(self.schema.clone(), arrays)
            .map_err(|e| LogError::Output { file: path.to_path_buf(), problem: format!("Parquet batch: {e}") })?;
        self.writer.write(&batch).map_err(fail)?;
        self.writer.flush().map_err(fail)
    }

    pub(crate) fn finish(mut self, path: &Path) -> Result<File> {
        self.flush_group(path)?;
        self.writer
            .into_inner()
            .map_err(|e| LogError::Output { file: path.to_path_buf(), problem: format!("Parquet footer: {e}") })
    }
}
