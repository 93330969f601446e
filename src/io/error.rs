//! The crate's error type: every variant names the file, and where it applies the row, column, value and unit.

use std::fmt;
use std::path::PathBuf;

/// Result with [`LogError`].
pub type Result<T> = std::result::Result<T, LogError>;

/// Where in a file a problem is: the 1-based data row and, for text files, the 1-based file line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Location {
    /// 1-based data row (header and comment lines are not counted); 0 when not at a row.
    pub row: u64,
    /// 1-based line of the file (text formats only).
    pub line: Option<u64>,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            // Not at a data row: a header line.
            Some(line) if self.row == 0 => write!(f, "line {line}"),
            Some(line) => write!(f, "data row {} (line {line})", self.row),
            None => write!(f, "data row {}", self.row),
        }
    }
}

/// Why a frame name or matrix was refused (see [`crate::io::frame_matrix`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FrameError {
    /// The name is not three axis letters (F/B/R/L/U/D) nor a known alias.
    #[error(
        "unknown frame name {name:?}: use three axis letters from F(orward) B(ack) R(ight) L(eft) U(p) D(own), e.g. \"frd\", \"flu\", \"rfu\", or the aliases enu, ned, nwu"
    )]
    UnknownName {
        /// The name given.
        name: String,
    },
    /// The letters do not span three perpendicular axes (e.g. "ffd").
    #[error("frame {name:?} names the same axis twice: each of forward/back, right/left, up/down must appear once")]
    RepeatedAxis {
        /// The name given.
        name: String,
    },
    /// The axes form a left-handed triad, which no IMU reports.
    #[error("frame {name:?} is left-handed (x × y points {z_would_be}, not along z): an IMU frame is right-handed")]
    LeftHanded {
        /// The name given.
        name: String,
        /// Where x × y points, as a word.
        z_would_be: &'static str,
    },
    /// An explicit matrix that is not a rotation.
    #[error(
        "the frame matrix is not a rotation (orthonormality error {orthonormality_error:.3e}, determinant {determinant:.6}); give the matrix that maps the file's axes onto RFU"
    )]
    NotARotation {
        /// max |Cᵀ C − I|.
        orthonormality_error: f64,
        /// det C.
        determinant: f64,
    },
}

/// Everything that can go wrong reading or writing a log. The message always starts with the file.
#[derive(Debug, thiserror::Error)]
pub enum LogError {
    /// The file could not be opened, read or written.
    #[error("{}: {action}: {source}", .file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// What we were doing ("cannot open", "cannot read", ...).
        action: &'static str,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// The content is not the format its extension says (or not a format we read).
    #[error("{}: the file is named as {expected} but {found}", .file.display())]
    NotTheFormat {
        /// The file.
        file: PathBuf,
        /// The format the extension promises ("a .npy file (NumPy)").
        expected: String,
        /// What the content looks like.
        found: String,
    },
    /// The file is of the right kind but damaged or unsupported (bad header, truncated, corrupt chunk...).
    #[error("{}: {detail}", .file.display())]
    Corrupt {
        /// The file.
        file: PathBuf,
        /// What is wrong.
        detail: String,
    },
    /// A requested column does not exist.
    #[error("{}: no column {column}; the file has {}", .file.display(), list(.available))]
    MissingColumn {
        /// The file.
        file: PathBuf,
        /// The column asked for (name, or "index N").
        column: String,
        /// The columns that exist.
        available: Vec<String>,
    },
    /// A cell that is not a number.
    #[error("{}: {at}, column {column}: {value:?} is not a number", .file.display())]
    NonNumeric {
        /// The file.
        file: PathBuf,
        /// Row and line.
        at: Location,
        /// Column name.
        column: String,
        /// The cell text (cut to 40 characters).
        value: String,
    },
    /// A NaN or infinite cell.
    #[error("{}: {at}, column {column}: the value is {value} (a log's values must be finite numbers)", .file.display())]
    NonFinite {
        /// The file.
        file: PathBuf,
        /// Row and line.
        at: Location,
        /// Column name.
        column: String,
        /// The value as text ("NaN", "inf", "null").
        value: String,
    },
    /// A number that cannot stand where it is (a PSINS count with a fraction, a sampling interval
    /// that is not positive, ...).
    #[error("{}: {at}, column {column}: {value:?} {problem}", .file.display())]
    BadValue {
        /// The file.
        file: PathBuf,
        /// Row and line (row 0: a header line).
        at: Location,
        /// Column name.
        column: String,
        /// The cell text (cut to 40 characters).
        value: String,
        /// Why it cannot be, and what is expected.
        problem: String,
    },
    /// A row with a different number of fields than the header (or the first row).
    #[error("{}: {at}: {found} fields where the {reference} has {expected}{}", .file.display(), if *.truncated_last_line { "; this is the last line and it has no line end: the file looks truncated (cut off while being written?)" } else { "" })]
    FieldCount {
        /// The file.
        file: PathBuf,
        /// Row and line.
        at: Location,
        /// Fields in the header (or first row).
        expected: usize,
        /// Fields in this row.
        found: usize,
        /// "header" or "first data row".
        reference: &'static str,
        /// The short row is the file's last line and has no line end.
        truncated_last_line: bool,
    },
    /// The file's last data line has no line end: it was cut off (while being written?), perhaps
    /// inside a number ("0.0316" → "0.0"), which no check of the value could see.
    #[error("{}: {at}: the last line has no line end: the file looks truncated (cut off while being written?), perhaps inside its last number; if the line is complete, end the file with a line break", .file.display())]
    TruncatedLine {
        /// The file.
        file: PathBuf,
        /// Row and line.
        at: Location,
    },
    /// A .npy with an element type we do not read.
    #[error("{}: the array's dtype is {dtype:?}; expected float64 ('<f8') or float32 ('<f4'), save with arr.astype(np.float64)", .file.display())]
    NpyDtype {
        /// The file.
        file: PathBuf,
        /// The descr string of the header.
        dtype: String,
    },
    /// An array or table of the wrong shape for what was asked.
    #[error("{}: shape {shape}: {expected}", .file.display())]
    Shape {
        /// The file.
        file: PathBuf,
        /// The shape found, e.g. "(100, 3)".
        shape: String,
        /// What was expected.
        expected: String,
    },
    /// A column of a type that is not a number (text, list, struct...).
    #[error("{}: column {column} has type {found}; numeric columns only (float64, float32, int64, int32, uint32, timestamp)", .file.display())]
    ColumnType {
        /// The file.
        file: PathBuf,
        /// Column name.
        column: String,
        /// The column's type.
        found: String,
    },
    /// A column whose name carries no unit we know, or a unit of the wrong quantity.
    #[error("{}: column {column}: {problem}", .file.display())]
    Unit {
        /// The file.
        file: PathBuf,
        /// Column name.
        column: String,
        /// What is wrong and what is accepted.
        problem: String,
    },
    /// The columns do not form an IMU layout.
    #[error("{}: {problem}", .file.display())]
    Layout {
        /// The file.
        file: PathBuf,
        /// What is missing or inconsistent.
        problem: String,
    },
    /// A time stamp before the previous one.
    #[error("{}: {at}: time goes backwards: {t} after {t_prev} (column {column})", .file.display())]
    NonMonotonicTime {
        /// The file.
        file: PathBuf,
        /// Row and line.
        at: Location,
        /// Time column.
        column: String,
        /// The previous row's time with its unit.
        t_prev: String,
        /// This row's time with its unit.
        t: String,
    },
    /// A time stamp equal to the previous one.
    #[error("{}: {at}: duplicated time stamp {t} (same as the previous row, column {column})", .file.display())]
    DuplicateTime {
        /// The file.
        file: PathBuf,
        /// Row and line.
        at: Location,
        /// Time column.
        column: String,
        /// The repeated time with its unit.
        t: String,
    },
    /// A gap larger than the allowed multiple of the nominal interval (policy Refuse).
    #[error("{}: {at}: gap of {} s ({} × the nominal {} s) between t = {} s and {} s (relative to the first sample); set gap_policy = \"split\" in the manifest's [imu] to carry the attitude across it", .file.display(), fixed_number(*.gap_s, 6), fixed_number(*.multiple, 1), fixed_number(*.nominal_s, 6), fixed_number(*.t_before_s, 6), fixed_number(*.t_after_s, 6))]
    Gap {
        /// The file.
        file: PathBuf,
        /// Row and line of the sample after the gap.
        at: Location,
        /// Time of the sample before the gap, s since the first sample.
        t_before_s: f64,
        /// Time of the sample after the gap, s since the first sample.
        t_after_s: f64,
        /// Length of the interval, s.
        gap_s: f64,
        /// The nominal sampling interval, s.
        nominal_s: f64,
        /// gap_s / nominal_s.
        multiple: f64,
    },
    /// The static-segment plausibility check failed.
    #[error("{}: {message}", .file.display())]
    Implausible {
        /// The file.
        file: PathBuf,
        /// What the data look like, and what to set.
        message: String,
    },
    /// A bad frame name or matrix.
    #[error("{}: {source}", .file.display())]
    Frame {
        /// The file.
        file: PathBuf,
        /// Why.
        #[source]
        source: FrameError,
    },
    /// MCAP: the Imu topic could not be chosen.
    #[error("{}: {problem}; the file's topics are {}", .file.display(), list(.topics))]
    Topic {
        /// The file.
        file: PathBuf,
        /// What went wrong.
        problem: String,
        /// "topic (schema, encoding)" for every channel.
        topics: Vec<String>,
    },
    /// Writers: the output or its `.partial` sibling is in the way.
    #[error("{}: {problem}", .file.display())]
    Output {
        /// The file being written.
        file: PathBuf,
        /// What is in the way.
        problem: String,
    },
}

fn list(items: &[String]) -> String {
    if items.is_empty() { "none".to_owned() } else { items.join(", ") }
}

impl LogError {
    /// The file the error is about.
    #[must_use]
    pub fn file(&self) -> &std::path::Path {
        match self {
            Self::Io { file, .. }
            | Self::NotTheFormat { file, .. }
            | Self::Corrupt { file, .. }
            | Self::MissingColumn { file, .. }
            | Self::NonNumeric { file, .. }
            | Self::NonFinite { file, .. }
            | Self::BadValue { file, .. }
            | Self::FieldCount { file, .. }
            | Self::TruncatedLine { file, .. }
            | Self::NpyDtype { file, .. }
            | Self::Shape { file, .. }
            | Self::ColumnType { file, .. }
            | Self::Unit { file, .. }
            | Self::Layout { file, .. }
            | Self::NonMonotonicTime { file, .. }
            | Self::DuplicateTime { file, .. }
            | Self::Gap { file, .. }
            | Self::Implausible { file, .. }
            | Self::Frame { file, .. }
            | Self::Topic { file, .. }
            | Self::Output { file, .. } => file,
        }
    }

    pub(crate) fn io(file: &std::path::Path, action: &'static str, source: std::io::Error) -> Self {
        Self::Io { file: file.to_path_buf(), action, source }
    }

    pub(crate) fn corrupt(file: &std::path::Path, detail: impl Into<String>) -> Self {
        Self::Corrupt { file: file.to_path_buf(), detail: detail.into() }
    }
}

/// A number as a message shows it: as Rust writes it for everyday sizes, in exponent form beyond
/// them (`1e300`, never 301 digits).
#[must_use]
pub fn short_number(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 || !v.is_finite() || (1e-4..1e9).contains(&a) { format!("{v}") } else { format!("{v:e}") }
}

/// A number with `decimals` fixed decimals where it is of an everyday size, else as
/// [`short_number`] (`{:.6}` of 1e300 has 307 characters).
#[must_use]
pub fn fixed_number(v: f64, decimals: usize) -> String {
    if v.is_finite() && v.abs() < 1e9 { format!("{v:.decimals$}") } else { short_number(v) }
}

/// Cuts a cell's text for an error message.
pub(crate) fn cell_text(bytes: &[u8]) -> String {
    let s = String::from_utf8_lossy(bytes);
    let mut out: String = s.chars().take(40).collect();
    if s.chars().count() > 40 {
        out.push('…');
    }
    out
}
