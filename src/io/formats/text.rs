//! Delimited text tables: CSV with a header, or whitespace/comma-separated numbers without one.
//!
//! Rules (they cover rinscope's CSV, PSINS and KF-GINS text dumps and EuRoC/Kalibr `imu0.csv`):
//! * Blank lines are skipped anywhere; `#` comment lines are allowed before the first table line.
//! * A UTF-8 byte-order mark and `\r\n` line ends are accepted.
//! * The delimiter comes from the first table line: if it holds a comma the file is comma-separated
//!   (fields are trimmed of spaces and tabs, empty fields are errors); otherwise fields are separated
//!   by runs of spaces, tabs or commas (the KF-GINS loader's rule).
//! * Header ([`HeaderMode::Auto`]): the first table line is the header if any of its fields is not a
//!   number. If it is all numbers, the last `#` comment line becomes the header when it has the same
//!   number of fields (EuRoC/Kalibr write `#timestamp [ns],w_RS_S_x [rad s^-1],...`); else there is none.
//! * Columns without a header are named `index 0`, `index 1`, ...
//! * Every row must have as many fields as the header (or, without one, as the first row), and end
//!   with a line end: a last line without one was cut off, perhaps inside a number.
//! * Lines are read one at a time (at most 1 MiB each): memory does not grow with the file.

use crate::io::error::{Location, LogError, Result, cell_text};
use crate::io::formats::table::{HeaderMode, Source};
use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

const MAX_LINE_BYTES: u64 = 1 << 20;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Delimiter {
    Comma,
    Whitespace,
}

/// One line read from the file.
pub(crate) struct Line {
    /// The line without its `\r\n` or `\n` (and without a UTF-8 byte-order mark on line 1).
    pub bytes: Vec<u8>,
    /// 1-based line number.
    pub number: u64,
    /// The line ended with `\n` (false only for the file's last line).
    pub terminated: bool,
}

/// A text file's lines, one at a time (at most [`MAX_LINE_BYTES`] each), numbered from 1.
pub(crate) struct LineReader {
    path: PathBuf,
    reader: BufReader<File>,
    line_number: u64,
    first_line: bool,
    /// Bytes read so far, the last line's, where the data rows start (after a header), and the
    /// file's length (0: not known, a pipe).
    bytes_read: u64,
    last_line_bytes: u64,
    data_from: Option<u64>,
    file_len: u64,
}

/// The mean length of the whole lines in the last `TAIL` bytes of a file of `len` bytes (a line's
/// length changes along a log: its time stamp gains digits); None for a file under 4 × `TAIL`.
fn tail_line_bytes(path: &Path, len: u64) -> Option<f64> {
    use std::io::{Seek, SeekFrom};
    const TAIL: u64 = 1 << 16;
    if len < 4 * TAIL {
        return None;
    }
    let mut file = crate::io::files::open_input(path).ok()?;
    file.seek(SeekFrom::Start(len - TAIL)).ok()?;
    let mut tail = Vec::with_capacity(TAIL as usize);
    file.take(TAIL).read_to_end(&mut tail).ok()?;
    let first = tail.iter().position(|&b| b == b'\n')? + 1;
    let last = tail.iter().rposition(|&b| b == b'\n')? + 1;
    let lines = tail[first..last].iter().filter(|&&b| b == b'\n').count();
    (lines > 0).then(|| (last - first) as f64 / lines as f64)
}

impl LineReader {
    pub(crate) fn open(path: &Path) -> Result<Self> {
        let file = crate::io::files::open_input(path).map_err(|e| LogError::io(path, "cannot open", e))?;
        let file_len = file.metadata().map_or(0, |m| if m.is_file() { m.len() } else { 0 });
        Ok(Self {
            path: path.to_path_buf(),
            reader: BufReader::with_capacity(1 << 16, file),
            line_number: 0,
            first_line: true,
            bytes_read: 0,
            last_line_bytes: 0,
            data_from: None,
            file_len,
        })
    }

    /// Reads the next line into `bytes` (cleared first: pass a used buffer to reuse it); `None`
    /// at end of file.
    pub(crate) fn next_line(&mut self, mut bytes: Vec<u8>) -> Result<Option<Line>> {
        bytes.clear();
        let n = (&mut self.reader)
            .take(MAX_LINE_BYTES)
            .read_until(b'\n', &mut bytes)
            .map_err(|e| LogError::io(&self.path, "cannot read", e))?;
        if n == 0 {
            return Ok(None);
        }
        self.line_number += 1;
        self.bytes_read += n as u64;
        self.last_line_bytes = n as u64;
        let terminated = bytes.last() == Some(&b'\n');
        if !terminated && n as u64 == MAX_LINE_BYTES {
            return Err(LogError::corrupt(
                &self.path,
                format!(
                    "line {} is longer than {MAX_LINE_BYTES} bytes: this is not a line-oriented text table",
                    self.line_number
                ),
            ));
        }
        while matches!(bytes.last(), Some(b'\n' | b'\r')) {
            bytes.pop();
        }
        if self.first_line {
            self.first_line = false;
            if bytes.starts_with(b"\xEF\xBB\xBF") {
                bytes.drain(..3);
            }
        }
        Ok(Some(Line { bytes, number: self.line_number, terminated }))
    }

    /// The number of the last line read (0 before the first).
    pub(crate) fn line_number(&self) -> u64 {
        self.line_number
    }

    /// Marks the last line read as the first data row (what precedes it is a header).
    pub(crate) fn mark_first_row(&mut self) {
        self.data_from.get_or_insert(self.bytes_read - self.last_line_bytes);
    }

    /// The rows the whole file holds, estimated from the `rows` read so far: the data's bytes after
    /// the header over a row's mean length, the mean of the rows read and of the file's last lines
    /// (exact for lines growing at a steady rate; the tail is read here, by the one caller that
    /// asks, not at every opening); None before a row, or for a pipe.
    pub(crate) fn rows_estimate(&self, rows: u64) -> Option<u64> {
        let from = self.data_from?;
        let read = self.bytes_read.saturating_sub(from);
        if rows == 0 || read == 0 || self.file_len <= from {
            return None;
        }
        let head = read as f64 / rows as f64;
        let mean = tail_line_bytes(&self.path, self.file_len).map_or(head, |tail| 0.5 * (head + tail));
        Some(((self.file_len - from) as f64 / mean).round() as u64)
    }
}

pub(crate) struct TextSource {
    path: PathBuf,
    lines: LineReader,
    delimiter: Delimiter,
    names: Vec<String>,
    has_header: bool,
    field_count: usize,
    pending: Option<Line>,
    current: Line,
    spans: Vec<(usize, usize)>,
    selected: Vec<usize>,
    row: u64,
}

pub(crate) fn is_blank(s: &[u8]) -> bool {
    s.iter().all(|b| b.is_ascii_whitespace())
}

fn trim(s: &[u8]) -> &[u8] {
    let start = s.iter().position(|b| !matches!(b, b' ' | b'\t')).unwrap_or(s.len());
    let end = s.iter().rposition(|b| !matches!(b, b' ' | b'\t')).map_or(start, |e| e + 1);
    s.get(start..end).unwrap_or(&[])
}

/// Field spans of `line` (byte ranges, trimmed).
pub(crate) fn split(line: &[u8], delimiter: Delimiter, spans: &mut Vec<(usize, usize)>) {
    spans.clear();
    match delimiter {
        Delimiter::Comma => {
            let mut start = 0;
            for (i, &b) in line.iter().enumerate().chain(std::iter::once((line.len(), &b','))) {
                if b == b',' {
                    let (mut s, mut e) = (start, i);
                    while s < e && matches!(line[s], b' ' | b'\t') {
                        s += 1;
                    }
                    while e > s && matches!(line[e - 1], b' ' | b'\t') {
                        e -= 1;
                    }
                    spans.push((s, e));
                    start = i + 1;
                }
            }
        }
        Delimiter::Whitespace => {
            let mut start = None;
            for (i, &b) in line.iter().enumerate() {
                let sep = matches!(b, b' ' | b'\t' | b',');
                match (sep, start) {
                    (false, None) => start = Some(i),
                    (true, Some(s)) => {
                        spans.push((s, i));
                        start = None;
                    }
                    _ => {}
                }
            }
            if let Some(s) = start {
                spans.push((s, line.len()));
            }
        }
    }
}

pub(crate) fn field(line: &[u8], span: (usize, usize)) -> &[u8] {
    line.get(span.0..span.1).unwrap_or(&[])
}

fn is_number(s: &[u8]) -> bool {
    std::str::from_utf8(s).is_ok_and(|t| t.parse::<f64>().is_ok())
}

fn header_name(s: &[u8]) -> String {
    let s = trim(s);
    let s = s.strip_prefix(b"\"").and_then(|t| t.strip_suffix(b"\"")).unwrap_or(s);
    String::from_utf8_lossy(s).trim().to_owned()
}

/// Parses a numeric cell: the f64 value, and the exact integer when the text is a plain integer.
pub(crate) fn parse_cell(text: &[u8]) -> Option<(f64, Option<i64>)> {
    let s = std::str::from_utf8(text).ok()?;
    let value = s.parse::<f64>().ok()?;
    let digits = s.strip_prefix(['+', '-']).unwrap_or(s);
    let exact = if !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) {
        s.strip_prefix('+').unwrap_or(s).parse::<i64>().ok()
    } else {
        None
    };
    Some((value, exact))
}

impl TextSource {
    pub(crate) fn open(path: &Path, header: HeaderMode) -> Result<Self> {
        let mut source = Self {
            path: path.to_path_buf(),
            lines: LineReader::open(path)?,
            delimiter: Delimiter::Comma,
            names: Vec::new(),
            has_header: false,
            field_count: 0,
            pending: None,
            current: Line { bytes: Vec::new(), number: 0, terminated: true },
            spans: Vec::new(),
            selected: Vec::new(),
            row: 0,
        };
        source.read_preamble(header)?;
        Ok(source)
    }

    fn read_preamble(&mut self, mode: HeaderMode) -> Result<()> {
        let mut last_comment: Option<Vec<u8>> = None;
        let first = loop {
            let Some(line) = self.lines.next_line(Vec::new())? else {
                break None;
            };
            if is_blank(&line.bytes) {
                continue;
            }
            if let Some(rest) = line.bytes.strip_prefix(b"#") {
                last_comment = Some(rest.to_vec());
                continue;
            }
            break Some(line);
        };
        let Some(first) = first else {
            // No table line: a header-only file (possibly in a comment) has zero rows.
            if let (Some(comment), false) = (last_comment, mode == HeaderMode::Absent) {
                self.delimiter = if comment.contains(&b',') { Delimiter::Comma } else { Delimiter::Whitespace };
                split(&comment, self.delimiter, &mut self.spans);
                self.names = self.spans.iter().map(|&s| header_name(field(&comment, s))).collect();
                self.has_header = true;
                self.field_count = self.names.len();
                return Ok(());
            }
            return Err(LogError::corrupt(&self.path, "the file has no table: no header and no data rows"));
        };
        self.delimiter = if first.bytes.contains(&b',') { Delimiter::Comma } else { Delimiter::Whitespace };
        split(&first.bytes, self.delimiter, &mut self.spans);
        let all_numbers = self.spans.iter().all(|&s| is_number(field(&first.bytes, s)));
        let count = self.spans.len();
        let comment_header = last_comment.filter(|c| {
            let mut spans = Vec::new();
            split(c, self.delimiter, &mut spans);
            spans.len() == count
        });
        let header_line: Option<Vec<u8>> = match mode {
            HeaderMode::Absent => None,
            HeaderMode::Auto | HeaderMode::Present if all_numbers && comment_header.is_some() => comment_header,
            HeaderMode::Auto if all_numbers => None,
            HeaderMode::Auto | HeaderMode::Present => Some(first.bytes.clone()),
        };
        match header_line {
            Some(h) => {
                let is_first = h == first.bytes;
                split(&h, self.delimiter, &mut self.spans);
                self.names = self.spans.iter().map(|&s| header_name(field(&h, s))).collect();
                self.has_header = true;
                self.field_count = self.names.len();
                if !is_first {
                    self.pending = Some(first);
                }
            }
            None => {
                self.names = (0..count).map(|i| format!("index {i}")).collect();
                self.field_count = count;
                self.pending = Some(first);
            }
        }
        Ok(())
    }
}

impl Source for TextSource {
    fn all_columns(&self) -> &[String] {
        &self.names
    }

    fn select(&mut self, indices: &[usize]) -> Result<()> {
        self.selected = indices.to_vec();
        Ok(())
    }

    fn next_row(&mut self, out: &mut [f64], exact: &mut [Option<i64>]) -> Result<bool> {
        let line = loop {
            let next = match self.pending.take() {
                Some(line) => Some(line),
                None => {
                    let reuse = std::mem::take(&mut self.current.bytes);
                    self.lines.next_line(reuse)?
                }
            };
            let Some(line) = next else { return Ok(false) };
            if is_blank(&line.bytes) {
                self.current.bytes = line.bytes;
                continue;
            }
            break line;
        };
        self.current = line;
        self.row += 1;
        if self.row == 1 {
            self.lines.mark_first_row();
        }
        split(&self.current.bytes, self.delimiter, &mut self.spans);
        if self.spans.len() != self.field_count {
            return Err(LogError::FieldCount {
                file: self.path.clone(),
                at: self.location(),
                expected: self.field_count,
                found: self.spans.len(),
                reference: if self.has_header { "header" } else { "first data row" },
                truncated_last_line: !self.current.terminated && self.spans.len() < self.field_count,
            });
        }
        if !self.current.terminated {
            return Err(LogError::TruncatedLine { file: self.path.clone(), at: self.location() });
        }
        for (k, &col) in self.selected.iter().enumerate() {
            let span = self.spans.get(col).copied().unwrap_or((0, 0));
            let text = field(&self.current.bytes, span);
            let Some((value, integer)) = parse_cell(text) else {
                return Err(LogError::NonNumeric {
                    file: self.path.clone(),
                    at: self.location(),
                    column: self.names.get(col).cloned().unwrap_or_default(),
                    value: cell_text(text),
                });
            };
            if let (Some(o), Some(e)) = (out.get_mut(k), exact.get_mut(k)) {
                *o = value;
                *e = integer;
            }
        }
        Ok(true)
    }

    fn selected_width(&self) -> usize {
        self.selected.len()
    }

    fn location(&self) -> Location {
        Location { row: self.row, line: Some(self.current.number) }
    }

    fn rows_hint(&self) -> Option<u64> {
        self.lines.rows_estimate(self.row)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spans(line: &str, d: Delimiter) -> Vec<String> {
        let mut s = Vec::new();
        split(line.as_bytes(), d, &mut s);
        s.iter().map(|&sp| String::from_utf8_lossy(field(line.as_bytes(), sp)).into_owned()).collect()
    }

    #[test]
    fn splitting() {
        assert_eq!(spans(" a , b,c ", Delimiter::Comma), ["a", "b", "c"]);
        assert_eq!(spans("1,,3", Delimiter::Comma), ["1", "", "3"]);
        assert_eq!(spans("  1.0\t2  3,4 ", Delimiter::Whitespace), ["1.0", "2", "3", "4"]);
        assert_eq!(spans("", Delimiter::Whitespace), Vec::<String>::new());
    }

    #[test]
    fn cells() {
        assert_eq!(parse_cell(b"1403715273262142976"), Some((1403715273262142976.0, Some(1403715273262142976))));
        assert_eq!(parse_cell(b"+12"), Some((12.0, Some(12))));
        assert_eq!(parse_cell(b"-1.5e-3"), Some((-1.5e-3, None)));
        assert!(parse_cell(b"abc").is_none());
        assert!(parse_cell(b"").is_none());
        assert!(parse_cell(b"NaN").is_some_and(|(v, _)| v.is_nan()));
    }
}
