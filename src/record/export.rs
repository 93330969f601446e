//! `--export DIR`: every time series a recording holds, also written as tables — one Parquet (or
//! CSV) file per entity, a `t_s` column and one column per series, the unit in each column's name
//! — for notebooks, MATLAB and spreadsheets (Rerun's own reader needs a server for .rrd files).
//! The files go through `FILE.partial` and appear when the run finishes.
//!
//! The same tables can be kept in memory instead ([`Exporter::in_memory`]): what the Python
//! package hands to pandas, with the same table and column names as the files.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use crate::io::{LogError, TableWriter};

/// The table format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExportFormat {
    /// Apache Parquet (pandas `read_parquet`, MATLAB `parquetread`).
    Parquet,
    /// CSV with a header.
    Csv,
}

impl ExportFormat {
    /// Parses "parquet" or "csv".
    pub fn parse(text: &str) -> Result<Self, String> {
        match text {
            "parquet" => Ok(Self::Parquet),
            "csv" => Ok(Self::Csv),
            other => Err(format!("\"{other}\" is not an export format; use parquet or csv")),
        }
    }

    fn extension(self) -> &'static str {
        match self {
            Self::Parquet => "parquet",
            Self::Csv => "csv",
        }
    }
}

/// Where the tables go.
enum Target {
    /// Files in a folder.
    Files { dir: PathBuf, format: ExportFormat },
    /// [`Table`]s in memory.
    Memory,
}

/// One table kept in memory: a file's columns, each a vector of values.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// The name its file would have, without the extension (`attitude_error_arcsec__heading`).
    pub name: String,
    /// The entity (or table name) it was written under (`attitude_error_arcsec/heading`).
    pub entity: String,
    /// The column names, as in the file.
    pub columns: Vec<String>,
    /// One vector per column, all the same length.
    pub values: Vec<Vec<f64>>,
}

/// A table being written: a file, or columns in memory.
enum Open {
    File(TableWriter),
    Memory(Table),
}

impl Open {
    fn columns(&self) -> &[String] {
        match self {
            Self::File(w) => w.columns(),
            Self::Memory(t) => &t.columns,
        }
    }

    fn write_row(&mut self, row: &[f64]) -> Result<(), LogError> {
        match self {
            Self::File(w) => w.write_row(row),
            Self::Memory(t) => {
                for (column, v) in t.values.iter_mut().zip(row) {
                    column.push(*v);
                }
                Ok(())
            }
        }
    }
}

/// The tables of one recording.
pub struct Exporter {
    target: Target,
    tables: BTreeMap<String, Open>,
    /// The first write that failed: the recording goes on, the run reports it at the end.
    failed: Option<LogError>,
    /// A replay's t = 0 on the IMU file's clock, s: every table then has `t_file_s` after `t_s`.
    file_clock_s: Option<f64>,
}

/// An exporter shared by the recorders of one run.
pub type SharedExporter = Arc<Mutex<Exporter>>;

/// The unit an entity path states: the unit suffix of its last segment that has one
/// (`attitude_error_arcsec/pitch` → arcsec).
#[must_use]
pub fn unit_of(entity: &str) -> Option<&'static str> {
    entity.rsplit('/').find_map(|seg| crate::io::imu::units::split_unit(seg).map(|(_, u)| u.suffix))
}

/// A series name as a column name: lower-case letters, digits and `_` (`+3σ` → `plus_3_sigma`,
/// `two-sample-p1` → `two_sample_p1`: a hyphen between letters or digits joins a name, elsewhere
/// `-` is a minus).
#[must_use]
pub fn column_base(name: &str) -> String {
    let mut out = String::new();
    let chars: Vec<char> = name.chars().collect();
    for (i, &ch) in chars.iter().enumerate() {
        let joins = |j: Option<usize>| j.and_then(|j| chars.get(j)).is_some_and(char::is_ascii_alphanumeric);
        let piece = match ch {
            '+' => "_plus_".to_owned(),
            '-' if joins(i.checked_sub(1)) && joins(Some(i + 1)) => "_".to_owned(),
            '−' | '-' => "_minus_".to_owned(),
            'σ' => "_sigma_".to_owned(),
            'α' => "_alpha_".to_owned(),
            'φ' => "_phi_".to_owned(),
            'η' => "_eta_".to_owned(),
            c if c.is_ascii_alphanumeric() => c.to_ascii_lowercase().to_string(),
            _ => "_".to_owned(),
        };
        out.push_str(&piece);
    }
    let parts: Vec<&str> = out.split('_').filter(|p| !p.is_empty()).collect();
    if parts.is_empty() { "value".to_owned() } else { parts.join("_") }
}

impl Exporter {
    /// Tables into `dir`, created if missing; its parent must exist, as for every output folder
    /// ([`crate::io::files::create_output_dir`]: a FIFO, a file, a symlink or a read-only folder is
    /// refused with what it is, not "File exists").
    ///
    /// # Errors
    /// Why the folder cannot be used.
    pub fn new(dir: &Path, format: ExportFormat) -> Result<Self, crate::io::files::OutputError> {
        crate::io::files::create_output_dir("--export", dir).map_err(|e| e.error)?;
        Ok(Self {
            target: Target::Files { dir: dir.to_path_buf(), format },
            tables: BTreeMap::new(),
            failed: None,
            file_clock_s: None,
        })
    }

    /// Tables kept in memory, taken with [`Self::finish`].
    #[must_use]
    pub fn in_memory() -> Self {
        Self { target: Target::Memory, tables: BTreeMap::new(), failed: None, file_clock_s: None }
    }

    /// A table named like `entity`'s file with `columns`: a file, or in memory.
    fn open(&self, entity: &str, columns: &[String], keyed: bool) -> Result<Open, LogError> {
        let refs: Vec<&str> = columns.iter().map(String::as_str).collect();
        Ok(match &self.target {
            Target::Files { dir, format } if keyed => Open::File(TableWriter::create_keyed(
                dir.join(format!("{}.{}", table_name(entity), format.extension())),
                &refs,
            )?),
            Target::Files { dir, format } => Open::File(TableWriter::create(
                dir.join(format!("{}.{}", table_name(entity), format.extension())),
                &refs,
            )?),
            Target::Memory => Open::Memory(Table {
                name: table_name(entity),
                entity: entity.to_owned(),
                columns: columns.to_vec(),
                values: vec![Vec::new(); columns.len()],
            }),
        })
    }

    /// A replay's t = 0 on the IMU file's clock, s: the tables created from now on have a
    /// `t_file_s` column (t_s + this) after `t_s`.
    pub fn set_file_clock(&mut self, t0_file_s: f64) {
        debug_assert!(self.tables.is_empty(), "the file clock is set before the first row");
        self.file_clock_s = Some(t0_file_s);
    }

    /// Appends rows to the table of `entity` (see [`Self::try_write`]); a failure is kept for
    /// [`Self::finish`] to report and later rows of that run are not written.
    pub fn write(&mut self, entity: &str, unit: &str, names: &[String], times: &[f64], values: &[f64]) {
        if self.failed.is_none()
            && let Err(e) = self.try_write(entity, unit, names, times, values)
        {
            self.failed = Some(e);
        }
    }

    /// Appends rows to the table of `entity`: `times` (s) and `values` row-major, one column per
    /// name, in `unit`.
    pub fn try_write(
        &mut self,
        entity: &str,
        unit: &str,
        names: &[String],
        times: &[f64],
        values: &[f64],
    ) -> Result<(), LogError> {
        let width = names.len();
        if !self.tables.contains_key(entity) {
            let mut columns = vec!["t_s".to_owned()];
            if self.file_clock_s.is_some() {
                columns.push("t_file_s".to_owned());
            }
            for name in names {
                let mut c = format!("{}_{unit}", column_base(name));
                while columns.contains(&c) {
                    c = format!("{}_{}_{unit}", column_base(name), columns.len());
                }
                columns.push(c);
            }
            let writer = self.open(entity, &columns, false)?;
            self.tables.insert(entity.to_owned(), writer);
        }
        let Some(writer) = self.tables.get_mut(entity) else { return Ok(()) };
        // The file clock's column if this table has it (a table created before the clock was set has not).
        let clock = self.file_clock_s.filter(|_| writer.columns().get(1).is_some_and(|c| c == "t_file_s"));
        let first = 1 + usize::from(clock.is_some());
        let mut row = vec![0.0; width + first];
        for (i, t) in times.iter().enumerate() {
            row[0] = *t;
            if let Some(t0) = clock {
                row[1] = t0 + t;
            }
            row[first..].copy_from_slice(&values[i * width..(i + 1) * width]);
            writer.write_row(&row)?;
        }
        Ok(())
    }

    /// Writes the whole table `name` (its file named like an entity's) that is not a time series:
    /// `columns`, the first one its key (`tau_s`, `axis`), and `rows` (see
    /// [`TableWriter::create_keyed`]).
    pub fn write_table(&mut self, name: &str, columns: &[String], rows: &[Vec<f64>]) -> Result<(), LogError> {
        let mut writer = self.open(name, columns, true)?;
        for row in rows {
            writer.write_row(row)?;
        }
        self.tables.insert(name.to_owned(), writer);
        Ok(())
    }

    /// Finishes every table, in the order of their names: the files' paths, or the tables kept in
    /// memory (the first failed write, if any, instead: the unfinished files are then removed).
    pub fn finish(&mut self) -> Result<Finished, LogError> {
        self.finish_until(&std::sync::atomic::AtomicBool::new(false))
    }

    /// [`Self::finish`], stopping between tables once `stop` is set: the tables finished until
    /// then are whole, the others are removed (never half-written) and counted in
    /// [`Finished::left`].
    pub fn finish_until(&mut self, stop: &std::sync::atomic::AtomicBool) -> Result<Finished, LogError> {
        let tables = std::mem::take(&mut self.tables);
        if let Some(e) = self.failed.take() {
            return Err(e);
        }
        let mut done = Finished::default();
        for table in tables.into_values() {
            if stop.load(std::sync::atomic::Ordering::SeqCst) {
                done.left += 1;
                continue;
            }
            match table {
                Open::File(writer) => {
                    let path = writer.path().to_path_buf();
                    writer.finish()?;
                    done.files.push(path);
                }
                Open::Memory(t) => done.tables.push(t),
            }
        }
        Ok(done)
    }
}

/// What [`Exporter::finish`] leaves: the files written, or the tables kept in memory.
#[derive(Debug, Default)]
pub struct Finished {
    /// The files' paths.
    pub files: Vec<PathBuf>,
    /// The tables kept in memory.
    pub tables: Vec<Table>,
    /// Tables not finished: a stop came first ([`Exporter::finish_until`]).
    pub left: usize,
}

/// A table's name, which is its file's name without the extension: the entity path with `/` as
/// `__` and `.` as `_`.
fn table_name(entity: &str) -> String {
    entity.trim_start_matches('/').replace('/', "__").replace('.', "_")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entity_units_and_column_names() {
        assert_eq!(unit_of("attitude_error_arcsec/pitch"), Some("arcsec"));
        assert_eq!(unit_of("ins/gyro_raw_deg_per_s"), Some("deg_per_s"));
        assert_eq!(unit_of("ins/position_error_m"), Some("m"));
        assert_eq!(column_base("+3σ"), "plus_3_sigma");
        assert_eq!(column_base("exact LSQ (final)"), "exact_lsq_final");
        assert_eq!(column_base("closed form"), "closed_form");
        // Algorithm names keep their words; a minus is still a minus.
        assert_eq!(column_base("two-sample-p1 heading error"), "two_sample_p1_heading_error");
        assert_eq!(column_base("-3σ"), "minus_3_sigma");
        assert_eq!(column_base("nominal − compensated table"), "nominal_minus_compensated_table");
    }

    /// The tables kept in memory are the files' tables: the same names, columns (the file clock, a
    /// repeated series name made unique) and values, checked against the CSV text the file target wrote.
    #[test]
    fn tables_in_memory_are_the_files_tables() {
        let dir = std::env::temp_dir().join(format!("rinscope-export-memory-{}", std::process::id()));
        let mut file = Exporter::new(&dir, ExportFormat::Csv).expect("folder");
        let mut memory = Exporter::in_memory();
        let names = vec!["uncompensated".to_owned(), "uncompensated".to_owned()];
        for e in [&mut file, &mut memory] {
            e.set_file_clock(100.0);
            e.write("attitude_error_arcsec/heading", "arcsec", &names, &[0.0, 0.5], &[1.0, 2.0, 3.0, 4.0]);
            e.write("attitude_error_arcsec/heading", "arcsec", &names, &[1.0], &[5.0, 6.0]);
            e.write_table("allan/gyro_fit", &["axis".to_owned(), "n_deg_per_sqrt_h".to_owned()], &[vec![0.0, 0.01]])
                .expect("table");
        }
        let written = file.finish().expect("files");
        assert!(written.tables.is_empty());
        let written = written.files;
        let in_memory = memory.finish().expect("tables");
        assert!(in_memory.files.is_empty());
        let tables = in_memory.tables;
        assert_eq!(tables.len(), written.len());
        for t in &tables {
            let path = dir.join(format!("{}.csv", t.name));
            assert!(written.contains(&path), "{}", path.display());
            let text = std::fs::read_to_string(&path).expect("csv");
            let mut lines = text.lines();
            assert_eq!(lines.next().expect("header").split(',').collect::<Vec<_>>(), t.columns, "{}", t.name);
            for (row, line) in lines.enumerate() {
                let cells: Vec<f64> = line.split(',').map(|c| c.parse().expect("number")).collect();
                let want: Vec<f64> = t.values.iter().map(|c| c[row]).collect();
                assert_eq!(cells, want, "{} row {row}", t.name);
            }
        }
        let heading = tables.iter().find(|t| t.entity == "attitude_error_arcsec/heading").expect("heading");
        assert_eq!(heading.columns, ["t_s", "t_file_s", "uncompensated_arcsec", "uncompensated_3_arcsec"]);
        assert_eq!(heading.values[1], [100.0, 100.5, 101.0]);
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_stop_while_the_tables_are_finished_keeps_whole_ones_and_removes_the_rest() {
        use std::sync::atomic::{AtomicBool, Ordering};
        let dir = std::env::temp_dir().join(format!("rinscope-export-stop-{}", std::process::id()));
        std::fs::remove_dir_all(&dir).ok();
        let names = ["a".to_owned()];
        let write_two = || {
            let mut e = Exporter::new(&dir, ExportFormat::Csv).expect("folder");
            e.write("x/first_m", "m", &names, &[0.0, 1.0], &[1.0, 2.0]);
            e.write("x/second_m", "m", &names, &[0.0, 1.0], &[3.0, 4.0]);
            e
        };
        // Not stopped: both tables, whole.
        let done = write_two().finish_until(&AtomicBool::new(false)).expect("finished");
        assert_eq!((done.files.len(), done.left), (2, 0));
        std::fs::remove_dir_all(&dir).ok();
        // Stopped before the first: none written, nothing half-written left behind.
        let stop = AtomicBool::new(false);
        let mut e = write_two();
        stop.store(true, Ordering::SeqCst);
        let done = e.finish_until(&stop).expect("finished");
        assert_eq!((done.files.len(), done.left), (0, 2));
        let left: Vec<_> = std::fs::read_dir(&dir).expect("folder").flatten().map(|f| f.file_name()).collect();
        assert!(left.is_empty(), "{left:?}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
