//! A series for `rinscope allan --series`: named or numbered columns of one table file (CSV or
//! whitespace text, `.npy`, Parquet — whatever [`ColumnReader`] reads), each with its kind and unit,
//! sampled at a declared rate or stamped by a time column. Returned as increments in SI, the form
//! every Allan-type estimator starts from (docs/allan.md, "Any series").
//!
//! | kind | what a value is | units | increment |
//! |---|---|---|---|
//! | `rate` | a rate over the sample interval | angular rate, acceleration | value·τ0 |
//! | `increment` | what accumulated over the interval | angle, velocity, time | value |
//! | `phase` | the accumulated quantity itself (a clock's time error, an angle) | angle, velocity, time | x_{k+1} − x_k |
//! | `frequency` | a fractional frequency y | `1`, `ppm`, `ppb`, `ppt` | y·τ0 (s) |

use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::io::error::{Location, LogError};
use crate::io::formats::table::{Col, ColumnReader, ReadOptions};
use crate::io::imu::units::{Quantity, Unit, unit_named, units_for};

/// What the values of a column are.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeriesKind {
    /// A rate (°/s, m/s², ...).
    Rate,
    /// An increment per sample (rad, m/s, ...).
    Increment,
    /// The accumulated quantity (a time error in s, an angle).
    Phase,
    /// A fractional frequency (dimensionless).
    Frequency,
}

impl SeriesKind {
    const ALL: [(Self, &'static str); 4] =
        [(Self::Rate, "rate"), (Self::Increment, "increment"), (Self::Phase, "phase"), (Self::Frequency, "frequency")];

    /// The name on the command line.
    #[must_use]
    pub fn name(self) -> &'static str {
        Self::ALL.iter().find(|(k, _)| *k == self).map_or("", |(_, n)| n)
    }

    /// The quantities a unit of this kind may measure.
    fn quantities(self) -> &'static [Quantity] {
        match self {
            Self::Rate => &[Quantity::AngularRate, Quantity::Acceleration],
            Self::Increment | Self::Phase => &[Quantity::Angle, Quantity::Velocity, Quantity::Time],
            Self::Frequency => &[Quantity::Dimensionless],
        }
    }

    /// The unit a value of this kind has when none is written.
    fn default_unit(self) -> Option<&'static str> {
        match self {
            Self::Frequency => Some("1"),
            Self::Phase => Some("s"),
            _ => None,
        }
    }
}

/// One column to analyse: `COLUMN:KIND[:UNIT]`.
#[derive(Debug, Clone, PartialEq)]
pub struct SeriesColumn {
    /// The column: a header name, or a 0-based position.
    pub col: Col,
    /// What its values are.
    pub kind: SeriesKind,
    /// Their unit.
    pub unit: Unit,
}

impl SeriesColumn {
    /// Parses `COLUMN:KIND[:UNIT]` (`gyro_z:rate:deg/s`, `2:frequency`, `x:phase:ns`); a column
    /// that is a whole number is a 0-based position. The unit is checked against the kind.
    ///
    /// # Errors
    /// A malformed spec, an unknown kind or unit, a unit of the wrong quantity — each named.
    pub fn parse(spec: &str) -> std::result::Result<Self, String> {
        let parts: Vec<&str> = spec.rsplitn(3, ':').collect();
        let kinds = || SeriesKind::ALL.iter().map(|(_, n)| *n).collect::<Vec<_>>().join(", ");
        let kind_of = |k: &str| SeriesKind::ALL.iter().find(|(_, n)| *n == k.trim()).map(|(k, _)| *k);
        // rsplitn from the right: [unit, kind, column] or [kind, column] (a unit-less kind).
        let (column, kind, unit) = match parts.as_slice() {
            [u, k, c] if kind_of(k).is_some() => (*c, kind_of(k), Some(*u)),
            [k, c] => (*c, kind_of(k), None),
            [u, k, c] => {
                // `a:b:c` whose middle is not a kind: the column name may hold a colon.
                match kind_of(u) {
                    Some(kind) => (&spec[..spec.len() - u.len() - 1], Some(kind), None),
                    None => {
                        return Err(format!(
                            "--column {spec:?}: {k:?} (after column {c:?}) is not a kind ({}); expected COLUMN:KIND[:UNIT], e.g. gyro_z:rate:deg/s",
                            kinds()
                        ));
                    }
                }
            }
            _ => {
                return Err(format!(
                    "--column {spec:?}: expected COLUMN:KIND[:UNIT], e.g. gyro_z:rate:deg/s, 2:frequency, x:phase:ns"
                ));
            }
        };
        let Some(kind) = kind else {
            return Err(format!("--column {spec:?}: the kind must be one of {}", kinds()));
        };
        if column.trim().is_empty() {
            return Err(format!("--column {spec:?}: no column named before the kind"));
        }
        let unit_text = unit.or(kind.default_unit()).ok_or_else(|| {
            let q: Vec<String> = kind.quantities().iter().map(|q| units_for(*q)).collect();
            format!("--column {spec:?}: a {} needs a unit ({})", kind.name(), q.join("; "))
        })?;
        let unit = unit_named(unit_text).ok_or_else(|| format!("--column {spec:?}: unknown unit {unit_text:?}"))?;
        if !kind.quantities().contains(&unit.quantity) {
            let q: Vec<String> = kind.quantities().iter().map(|q| units_for(*q)).collect();
            return Err(format!(
                "--column {spec:?}: {unit_text:?} is not a unit of a {} (use {})",
                kind.name(),
                q.join("; ")
            ));
        }
        let col = column.trim().parse::<usize>().map_or_else(|_| Col::Name(column.trim().to_owned()), Col::Index);
        Ok(Self { col, kind, unit })
    }

    /// The unit as a reader writes it (`deg/s`; `fractional` for a frequency in `1`).
    #[must_use]
    pub fn unit_text(&self) -> String {
        match self.unit.suffix {
            "1" => "fractional".to_owned(),
            u => u.replace("_per_", "/"),
        }
    }

    /// The SI quantity its increments are of: angle, velocity or time.
    #[must_use]
    pub fn increment_quantity(&self) -> Quantity {
        match self.unit.quantity {
            Quantity::AngularRate | Quantity::Angle => Quantity::Angle,
            Quantity::Acceleration | Quantity::Velocity => Quantity::Velocity,
            _ => Quantity::Time,
        }
    }
}

/// How the samples are spaced.
#[derive(Debug, Clone, PartialEq)]
pub enum Sampling {
    /// Evenly, at this rate (Hz).
    RateHz(f64),
    /// As a time column says (its unit), which must be even to 1 %.
    TimeColumn(Col, Unit),
}

/// The columns read.
#[derive(Debug, Clone)]
pub struct Series {
    /// Each column's header name (or `index N`).
    pub names: Vec<String>,
    /// The specs, in the same order.
    pub columns: Vec<SeriesColumn>,
    /// Each column's increments, SI (rad, m/s or s), one per sample interval.
    pub increments: Vec<Vec<f64>>,
    /// The sample interval, s.
    pub tau0_s: f64,
    /// Rows read.
    pub rows: usize,
    /// The reading was stopped (the stop flag of [`read_series_until`]) before the file's end:
    /// the series is the rows read until then.
    pub interrupted: bool,
}

/// Why a series cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum SeriesError {
    /// The file or a cell.
    #[error(transparent)]
    Log(#[from] LogError),
    /// The series as a whole (too short, a rate out of range, a time column that does not advance).
    #[error("{0}")]
    Series(String),
    /// Stopped (a signal) before two rows were read.
    #[error("{}: stopped after {rows} row(s), too few to analyse", .path.display())]
    Interrupted {
        /// The file.
        path: std::path::PathBuf,
        /// Rows read.
        rows: usize,
    },
}

/// Rows read between two looks at the stop flag: one batch (64k rows, a few ms of reading).
const STOP_CHECK_ROWS: usize = 65_536;

/// Largest relative spread of the time column's steps accepted as even sampling.
const EVEN_TOLERANCE: f64 = 0.01;

/// Reads `columns` of `path` sampled as `sampling` says, as increments in SI.
///
/// # Errors
/// The file or a column cannot be read (the error names the column, row and value), a time column
/// that does not advance evenly (the row), fewer than two rows, a rate out of range.
pub fn read_series(path: &Path, columns: &[SeriesColumn], sampling: &Sampling) -> Result<Series, SeriesError> {
    read_series_until(path, columns, sampling, &AtomicBool::new(false))
}

/// [`read_series`], looking at `stop` every [`STOP_CHECK_ROWS`] rows: once it is set, the rows read
/// so far are the series, marked [`Series::interrupted`] (a signal ends the reading of a 20 M-row
/// file within milliseconds, not after it).
///
/// # Errors
/// As [`read_series`]; [`SeriesError::Interrupted`] when stopped before two rows.
pub fn read_series_until(
    path: &Path,
    columns: &[SeriesColumn],
    sampling: &Sampling,
    stop: &AtomicBool,
) -> Result<Series, SeriesError> {
    let bad = |what: String| SeriesError::Series(format!("{}: {what}", path.display()));
    // A declared rate is checked before the file is read (the one number rule: a rate of 1e-308
    // Hz gave infinite increments and NaN deviations).
    let declared_tau0_s = match sampling {
        Sampling::RateHz(hz) => Some(tau0_of_rate(*hz, "--rate-hz").map_err(bad)?),
        Sampling::TimeColumn(..) => None,
    };
    let mut interrupted = false;
    let mut cols: Vec<Col> = columns.iter().map(|c| c.col.clone()).collect();
    if let Sampling::TimeColumn(t, _) = sampling {
        cols.push(t.clone());
    }
    let mut reader = ColumnReader::open(path, &cols, &ReadOptions::default())?;
    let names: Vec<String> = reader.columns()[..columns.len()].to_vec();
    let mut values: Vec<Vec<f64>> = vec![Vec::new(); columns.len()];
    let width = cols.len();
    let mut batch = Vec::with_capacity(width * STOP_CHECK_ROWS);
    let (mut t_first, mut t_prev, mut steps) = (None::<f64>, 0.0, Vec::new());
    loop {
        if stop.load(Ordering::Relaxed) {
            interrupted = true;
            break;
        }
        batch.clear();
        if reader.next_batch(&mut batch, STOP_CHECK_ROWS)? == 0 {
            break;
        }
        for row in batch.chunks_exact(width) {
            for (v, x) in values.iter_mut().zip(row) {
                v.push(*x);
            }
            if let Sampling::TimeColumn(_, unit) = sampling {
                let t = row[columns.len()] * unit.to_si;
                if t_first.is_some() {
                    steps.push(t - t_prev);
                }
                t_first.get_or_insert(t);
                t_prev = t;
            }
        }
    }
    let rows = values.first().map_or(0, Vec::len);
    if rows < 2 && interrupted {
        return Err(SeriesError::Interrupted { path: path.to_owned(), rows });
    }
    if rows < 2 {
        return Err(bad(format!("{rows} row(s): a series needs at least two samples")));
    }
    let tau0_s = match (declared_tau0_s, sampling) {
        (Some(tau0_s), _) => tau0_s,
        (None, Sampling::RateHz(hz)) => tau0_of_rate(*hz, "--rate-hz").map_err(bad)?,
        (None, Sampling::TimeColumn(..)) => match even_step(&steps) {
            Ok(()) => (t_prev - t_first.unwrap_or(0.0)) / (rows - 1) as f64,
            Err(Uneven::Stalled(median)) => {
                return Err(bad(format!(
                    "the time column does not advance (median step {} s)",
                    crate::io::short_number(median)
                )));
            }
            Err(Uneven::Step { k, step, median }) => {
                // Step k ends at data row k + 2 (1-based).
                let at = Location { row: k as u64 + 2, line: None };
                let time_col = &reader.columns()[columns.len()];
                return Err(SeriesError::Log(LogError::BadValue {
                    file: path.to_owned(),
                    at,
                    column: time_col.clone(),
                    value: format!("step {} s", crate::io::short_number(step)),
                    problem: uneven_problem(median),
                }));
            }
        },
    };
    Ok(Series {
        names,
        columns: columns.to_vec(),
        increments: increments(columns, values, tau0_s),
        tau0_s,
        rows,
        interrupted,
    })
}

/// The sample interval of a rate given as `name`, s (the one number rule,
/// [`crate::io::validity::SERIES_RATE_HZ`]).
fn tau0_of_rate(hz: f64, name: &str) -> Result<f64, String> {
    let hz = crate::io::validity::check_number(hz, &crate::io::validity::SERIES_RATE_HZ)
        .map_err(|e| format!("{name} {e}"))?;
    Ok(1.0 / hz)
}

/// Why a time axis is not evenly spaced.
enum Uneven {
    /// The median step is not positive.
    Stalled(f64),
    /// Step `k` (from sample k to k + 1) is off the median by more than [`EVEN_TOLERANCE`].
    Step { k: usize, step: f64, median: f64 },
}

/// Whether every step of `steps` (s) is within [`EVEN_TOLERANCE`] of their median.
fn even_step(steps: &[f64]) -> Result<(), Uneven> {
    let mut sorted = steps.to_vec();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    if median.is_nan() || median <= 0.0 {
        return Err(Uneven::Stalled(median));
    }
    match steps.iter().enumerate().find(|(_, d)| (*d / median - 1.0).abs() > EVEN_TOLERANCE) {
        Some((k, step)) => Err(Uneven::Step { k, step: *step, median }),
        None => Ok(()),
    }
}

fn uneven_problem(median: f64) -> String {
    format!(
        "where the series steps {} s: the Allan-type estimators need evenly spaced samples (a gap, or a jitter over {} %); cut the file at the gap or resample it",
        crate::io::short_number(median),
        EVEN_TOLERANCE * 100.0
    )
}

/// Each column's values as increments in SI, one per sample interval `tau0_s`.
fn increments(columns: &[SeriesColumn], values: Vec<Vec<f64>>, tau0_s: f64) -> Vec<Vec<f64>> {
    columns
        .iter()
        .zip(values)
        .map(|(c, v)| {
            let f = c.unit.to_si;
            match c.kind {
                SeriesKind::Rate | SeriesKind::Frequency => v.iter().map(|x| x * f * tau0_s).collect(),
                SeriesKind::Increment => v.iter().map(|x| x * f).collect(),
                SeriesKind::Phase => v.windows(2).map(|w| (w[1] - w[0]) * f).collect(),
            }
        })
        .collect()
}

/// A series given in memory (the Python package's arrays): `values` one vector per column of
/// `columns` (their `col` a name), sampled at `rate_hz` or at `times_s` (s). The same checks as
/// [`read_series`]: every value finite (the column and index named), equal lengths, at least two
/// samples, even sampling.
///
/// # Errors
/// Which column, index and value, or why the sampling is refused.
pub fn series_in_memory(
    columns: &[SeriesColumn],
    values: Vec<Vec<f64>>,
    rate_hz: Option<f64>,
    times_s: Option<&[f64]>,
) -> Result<Series, SeriesError> {
    let names: Vec<String> = columns
        .iter()
        .map(|c| match &c.col {
            Col::Name(n) => n.clone(),
            Col::Index(i) => i.to_string(),
        })
        .collect();
    let rows = values.first().map_or(0, Vec::len);
    for (name, v) in names.iter().zip(&values) {
        if v.len() != rows {
            return Err(SeriesError::Series(format!(
                "column {name}: {} samples where the first column has {rows}",
                v.len()
            )));
        }
        if let Some((i, x)) = v.iter().enumerate().find(|(_, x)| !x.is_finite()) {
            return Err(SeriesError::Series(format!("column {name}, sample {i}: {x} is not a finite number")));
        }
    }
    if rows < 2 {
        return Err(SeriesError::Series(format!("{rows} sample(s): a series needs at least two")));
    }
    let tau0_s = match (rate_hz, times_s) {
        (Some(hz), None) => tau0_of_rate(hz, "rate_hz").map_err(SeriesError::Series)?,
        (None, Some(t)) => {
            if t.len() != rows {
                return Err(SeriesError::Series(format!("time_s: {} times for {rows} samples", t.len())));
            }
            if let Some((i, x)) = t.iter().enumerate().find(|(_, x)| !x.is_finite()) {
                return Err(SeriesError::Series(format!("time_s, sample {i}: {x} s is not a finite number")));
            }
            let steps: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
            match even_step(&steps) {
                Ok(()) => (t[rows - 1] - t[0]) / (rows - 1) as f64,
                Err(Uneven::Stalled(median)) => {
                    return Err(SeriesError::Series(format!(
                        "time_s does not advance (median step {} s)",
                        crate::io::short_number(median)
                    )));
                }
                Err(Uneven::Step { k, step, median }) => {
                    return Err(SeriesError::Series(format!(
                        "time_s, from sample {k} to {}: step {step} s {}",
                        k + 1,
                        uneven_problem(median)
                    )));
                }
            }
        }
        _ => return Err(SeriesError::Series("give the sampling: rate_hz or time_s (not both)".into())),
    };
    Ok(Series {
        names,
        columns: columns.to_vec(),
        increments: increments(columns, values, tau0_s),
        tau0_s,
        rows,
        interrupted: false,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch_csv(name: &str, rows: usize) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("rinscope-series-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&d).expect("scratch");
        let path = d.join("s.csv");
        let mut text = String::from("x\n");
        for k in 0..rows {
            text.push_str(&format!("{}\n", (k % 7) as f64 * 0.1));
        }
        std::fs::write(&path, text).expect("csv");
        path
    }

    #[test]
    fn an_absurd_rate_is_refused_before_reading_and_said_short() {
        // Issue 31: --rate-hz 1e-308 gave a 1e308 s interval, infinite increments and NaN deviations.
        let path = scratch_csv("rate", 10);
        let col = [SeriesColumn::parse("x:rate:deg/s").expect("spec")];
        for hz in [1e-308, 1e308, -10.0, f64::NAN] {
            let e = read_series(&path, &col, &Sampling::RateHz(hz)).expect_err("refused").to_string();
            assert!(e.contains("--rate-hz") && e.contains("Hz") && e.len() < 200, "{hz}: {e}");
        }
        assert!(
            read_series(&path, &col, &Sampling::RateHz(1e-308)).expect_err("1e-308").to_string().contains("1e-308 Hz")
        );
        let s = read_series(&path, &col, &Sampling::RateHz(100.0)).expect("a good rate");
        assert!(!s.interrupted && s.rows == 10 && s.increments[0].iter().all(|x| x.is_finite()));
    }

    #[test]
    fn a_stop_ends_the_reading_at_the_next_batch() {
        // Issue 31: allan --series read a whole 20 M-row file after SIGTERM.
        let path = scratch_csv("stop", 3 * STOP_CHECK_ROWS);
        let col = [SeriesColumn::parse("x:rate:deg/s").expect("spec")];
        let stop = AtomicBool::new(true);
        let e = read_series_until(&path, &col, &Sampling::RateHz(100.0), &stop).expect_err("stopped before any row");
        assert!(matches!(e, SeriesError::Interrupted { rows: 0, .. }), "{e}");
        let whole = read_series_until(&path, &col, &Sampling::RateHz(100.0), &AtomicBool::new(false)).expect("whole");
        assert_eq!((whole.rows, whole.interrupted), (3 * STOP_CHECK_ROWS, false));
    }

    #[test]
    fn a_column_spec_names_its_column_kind_and_unit() {
        let c = SeriesColumn::parse("gyro_z:rate:deg/s").expect("valid");
        assert_eq!((c.col, c.kind, c.unit.suffix), (Col::Name("gyro_z".into()), SeriesKind::Rate, "deg_per_s"));
        let c = SeriesColumn::parse("2:frequency").expect("valid");
        assert_eq!((c.col, c.kind, c.unit.suffix), (Col::Index(2), SeriesKind::Frequency, "1"));
        let c = SeriesColumn::parse("x:phase:ns").expect("valid");
        assert_eq!((c.kind, c.unit.to_si), (SeriesKind::Phase, 1e-9));
        assert_eq!(
            SeriesColumn::parse("a:accel:rate:m/s^2").expect("a colon in the name").col,
            Col::Name("a:accel".into())
        );
        for (spec, says) in [
            ("gx:rate", "needs a unit"),
            ("gx:speed:deg/s", "kind"),
            ("gx:rate:furlong", "unknown unit"),
            ("gx:rate:ns", "not a unit of a rate"),
            ("gx", "expected COLUMN:KIND"),
        ] {
            let e = SeriesColumn::parse(spec).expect_err(spec);
            assert!(e.contains(says) && e.contains(spec), "{spec}: {e}");
        }
    }
}
